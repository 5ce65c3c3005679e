// The OFF reader (core/off_reader.h).
#include "core/off_reader.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "core/text_lines.h"

namespace palpate {
namespace {

std::string quote_word(std::string_view word) {
  std::string out(1, '\'');
  out.append(word.substr(0, 40));
  out.append(word.size() > 40 ? "...'" : "'");
  return out;
}

// "header declares 5 vertices and 2 faces, more than the 30-byte file can hold" (%g style for absurd counts)
std::string too_many(double nv, double nf, std::size_t bytes) {
  std::ostringstream msg;
  msg << std::setprecision(15) << "header declares " << nv << " vertices and " << nf << " faces, more than the "
      << bytes << "-byte file can hold";
  return msg.str();
}

// the lines of an OFF text that are neither blank nor comment, '#' comments cut off
class ContentLines {
 public:
  ContentLines(std::string_view text, std::size_t start, int64_t first_line) : lines_(text, start, first_line) {}
  bool next(std::vector<std::string_view>* words) {
    std::string_view line;
    while (lines_.next(&line)) {
      const std::size_t hash = line.find('#');
      if (hash != std::string_view::npos) line = line.substr(0, hash);
      split_words(line, words);
      if (!words->empty()) return true;
    }
    return false;
  }
  int64_t number() const { return lines_.number(); }
  std::size_t offset() const { return lines_.offset(); }

 private:
  TextLines lines_;
};

std::string at(int64_t line) { return "line " + std::to_string(line) + ": "; }

// big-endian 32-bit words after the "OFF BINARY" line
class BinaryWords {
 public:
  BinaryWords(std::string_view bytes, std::size_t start) : bytes_(bytes), pos_(start) {}
  std::size_t left() const { return bytes_.size() - pos_; }
  bool u32(uint32_t* out) {
    if (left() < 4) return false;
    const auto* b = reinterpret_cast<const unsigned char*>(bytes_.data() + pos_);
    *out = (uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | uint32_t{b[3]};
    pos_ += 4;
    return true;
  }
  bool i32(int64_t* out) {
    uint32_t u = 0;
    if (!u32(&u)) return false;
    *out = static_cast<int32_t>(u);
    return true;
  }
  bool f32(double* out) {
    uint32_t u = 0;
    if (!u32(&u)) return false;
    float f = 0;
    std::memcpy(&f, &u, 4);
    *out = f;
    return true;
  }

 private:
  std::string_view bytes_;
  std::size_t pos_;
};

Result<TriMesh> read_binary_off(std::string_view bytes, std::size_t start, bool dimension, int extra_floats) {
  BinaryWords in(bytes, start);
  int64_t ndim = 3, nv = 0, nf = 0, ne = 0;
  if (dimension && !in.i32(&ndim)) return Error{"binary OFF: the file ends before the dimension"};
  if (ndim != 3) return Error{"nOFF of dimension " + std::to_string(ndim) + ": only 3-dimensional vertices are read"};
  if (!in.i32(&nv) || !in.i32(&nf) || !in.i32(&ne)) return Error{"binary OFF: the file ends before the counts"};
  if (nv < 0 || nf < 0) return Error{"binary OFF: negative counts (" + std::to_string(nv) + " vertices, " + std::to_string(nf) + " faces)"};
  const int per_vertex = 3 + extra_floats;
  if (static_cast<double>(nv) * 4 * per_vertex + static_cast<double>(nf) * 8 > static_cast<double>(in.left()))
    return Error{too_many(static_cast<double>(nv), static_cast<double>(nf), bytes.size())};
  TriMesh mesh;
  mesh.vertices_m.resize(static_cast<std::size_t>(nv));
  for (int64_t v = 0; v < nv; ++v) {
    Vec3& p = mesh.vertices_m[static_cast<std::size_t>(v)];
    double skip = 0;
    if (!in.f32(&p.x()) || !in.f32(&p.y()) || !in.f32(&p.z())) return Error{"binary OFF: the file ends inside vertex " + std::to_string(v)};
    for (int k = 0; k < extra_floats; ++k)
      if (!in.f32(&skip)) return Error{"binary OFF: the file ends inside vertex " + std::to_string(v)};
  }
  std::vector<int32_t> polygon;
  for (int64_t f = 0; f < nf; ++f) {
    int64_t n = 0, colours = 0;
    if (!in.i32(&n)) return Error{"binary OFF: the file ends before face " + std::to_string(f)};
    if (n < 1) return Error{"binary OFF: face " + std::to_string(f) + " declares " + std::to_string(n) + " vertex indices"};
    if (static_cast<uint64_t>(n) * 4 > in.left())
      return Error{"binary OFF: face " + std::to_string(f) + " declares " + std::to_string(n) + " vertex indices, more than the " +
                   std::to_string(in.left()) + " bytes left in the file"};
    polygon.clear();
    for (int64_t k = 0; k < n; ++k) {
      int64_t index = 0;
      in.i32(&index);
      if (index < 0 || index >= nv)
        return Error{"face " + std::to_string(f) + " vertex index " + std::to_string(index) + " is beyond the vertex list (size " +
                     std::to_string(nv) + ")"};
      polygon.push_back(static_cast<int32_t>(index));
    }
    if (!in.i32(&colours) || colours < 0 || colours > 4)
      return Error{"binary OFF: face " + std::to_string(f) + ": the colour count is missing or not 0..4"};
    double skip = 0;
    for (int64_t k = 0; k < colours; ++k)
      if (!in.f32(&skip)) return Error{"binary OFF: the file ends inside face " + std::to_string(f)};
    append_polygon(mesh.vertices_m, polygon, &mesh.triangles);
  }
  return mesh;
}

}  // namespace

bool is_off_keyword(std::string_view word) {
  if (word.size() < 3 || word.substr(word.size() - 3) != "OFF") return false;
  word.remove_suffix(3);
  for (std::string_view prefix : {"ST", "C", "N", "4", "n"})
    if (word.substr(0, prefix.size()) == prefix) word.remove_prefix(prefix.size());
  return word.empty();
}

Result<TriMesh> read_off(std::string_view bytes) {
  ContentLines lines(bytes, 0, 1);
  std::vector<std::string_view> w;
  if (!lines.next(&w)) return Error{"no OFF header: the file holds only blank and comment lines"};
  std::size_t i = 0;  // the next word of w to read
  std::string keyword;
  if (w[0].find("OFF") != std::string_view::npos) {
    keyword = std::string(w[0]);
    if (!is_off_keyword(keyword))
      return Error{at(lines.number()) + "header keyword " + quote_word(keyword) + " is not [ST][C][N][4][n]OFF"};
    i = 1;
  } else {
    int64_t number = 0;
    if (!parse_integer(w[0], &number))
      return Error{at(lines.number()) + "the first word " + quote_word(w[0]) + " is neither an OFF keyword nor a vertex count"};
  }
  if (keyword.find('4') != std::string::npos)
    return Error{"4OFF (vertices in homogeneous coordinates x y z w) is not read: divide by w and save as OFF"};
  const bool dimension = keyword.find('n') != std::string::npos;
  const bool binary = i < w.size() && w[i] == "BINARY";
  // what follows x y z on a vertex line in this variant (binary only: text lines are read for their first three)
  const int extra_floats = (keyword.find('N') != std::string::npos ? 3 : 0) + (keyword.find('C') != std::string::npos ? 4 : 0) +
                           (keyword.find("ST") != std::string::npos ? 2 : 0);
  if (binary) {
    // the binary data starts just after the keyword line's end
    return read_binary_off(bytes, lines.offset(), dimension, extra_floats);
  }
  if (i < w.size() && !keyword.empty()) {
    int64_t number = 0;
    if (!parse_integer(w[i], &number))
      return Error{at(lines.number()) + quote_word(w[i]) + " after the keyword is not a count"};
  }
  // the counts (and nOFF's dimension before them) on the keyword line, else on the next lines
  auto next_words = [&]() {
    while (i >= w.size()) {
      if (!lines.next(&w)) return false;
      i = 0;
    }
    return true;
  };
  if (dimension) {
    int64_t ndim = 0;
    if (!next_words() || !parse_integer(w[i], &ndim)) return Error{"nOFF header: no dimension after the keyword"};
    if (ndim != 3) return Error{"nOFF of dimension " + std::to_string(ndim) + ": only 3-dimensional vertices are read"};
    ++i;
  }
  if (!next_words()) return Error{"OFF header: the file ends before the vertex and face counts"};
  const int64_t counts_line = lines.number();
  int64_t nv = -1, nf = -1;
  if (w.size() - i < 2) return Error{at(counts_line) + "OFF header: no vertex and face counts on one line"};
  if (!parse_integer(w[i], &nv) || !parse_integer(w[i + 1], &nf) || nv < 0 || nf < 0)
    return Error{at(counts_line) + "OFF header: the counts " + quote_word(w[i]) + " " + quote_word(w[i + 1]) +
                 " are not two whole numbers >= 0"};
  // at least "0 0 0" and a line end a vertex, "1 0" and a line end a face: checked before anything is reserved
  if (6.0 * static_cast<double>(nv) + 2.0 * static_cast<double>(nf) > static_cast<double>(bytes.size()))
    return Error{too_many(static_cast<double>(nv), static_cast<double>(nf), bytes.size())};
  if (nv > INT32_MAX) return Error{at(counts_line) + "OFF header: more than 2147483647 vertices"};
  TriMesh mesh;
  mesh.vertices_m.resize(static_cast<std::size_t>(nv));
  for (int64_t v = 0; v < nv; ++v) {
    if (!lines.next(&w)) return Error{"the file ends after " + std::to_string(v) + " of " + std::to_string(nv) + " vertices"};
    Vec3& p = mesh.vertices_m[static_cast<std::size_t>(v)];
    if (w.size() < 3) return Error{at(lines.number()) + "vertex " + std::to_string(v) + ": fewer than 3 coordinates on its line"};
    for (int c = 0; c < 3; ++c)
      if (!parse_real(w[static_cast<std::size_t>(c)], &p[c]))
        return Error{at(lines.number()) + "vertex " + std::to_string(v) + ": " + quote_word(w[static_cast<std::size_t>(c)]) +
                     " is not a number"};
  }
  std::vector<int32_t> polygon;
  for (int64_t f = 0; f < nf; ++f) {
    if (!lines.next(&w)) return Error{"the file ends after " + std::to_string(f) + " of " + std::to_string(nf) + " faces"};
    const std::string here = at(lines.number()) + "face " + std::to_string(f);
    int64_t n = 0;
    if (!parse_integer(w[0], &n)) return Error{here + ": " + quote_word(w[0]) + " is not a vertex count"};
    if (n < 1) return Error{here + " declares no vertex indices"};
    if (static_cast<uint64_t>(n) > w.size() - 1)
      return Error{here + " declares " + std::to_string(n) + " vertex indices, its line lists " + std::to_string(w.size() - 1)};
    polygon.clear();
    for (int64_t k = 1; k <= n; ++k) {
      int64_t index = 0;
      if (!parse_integer(w[static_cast<std::size_t>(k)], &index))
        return Error{here + ": " + quote_word(w[static_cast<std::size_t>(k)]) + " is not a vertex index"};
      if (index < 0 || index >= nv)
        return Error{here + " vertex index " + std::to_string(index) + " is beyond the vertex list (size " + std::to_string(nv) + ")"};
      polygon.push_back(static_cast<int32_t>(index));
    }
    append_polygon(mesh.vertices_m, polygon, &mesh.triangles);  // points and lines add nothing
  }
  return mesh;
}

}  // namespace palpate
