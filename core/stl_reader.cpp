// The STL reader (core/stl_reader.h).
#include "core/stl_reader.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <string>
#include <vector>

#include "core/text_lines.h"

namespace palpate {
namespace {

uint32_t le32(std::string_view b, std::size_t at) {
  uint32_t u = 0;
  for (int k = 3; k >= 0; --k) u = (u << 8) | static_cast<unsigned char>(b[at + static_cast<std::size_t>(k)]);
  return u;
}

bool same_word(std::string_view word, std::string_view keyword) {
  return word.size() == keyword.size() &&
         std::equal(word.begin(), word.end(), keyword.begin(),
                    [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
}

Result<TriMesh> read_binary(std::string_view bytes, uint64_t n) {
  TriMesh mesh;
  mesh.vertices_m.resize(3 * n);
  mesh.triangles.resize(n);
  for (uint64_t t = 0; t < n; ++t) {
    const std::size_t at = 84 + 50 * t + 12;  // past the normal
    for (int c = 0; c < 3; ++c) {
      Vec3& p = mesh.vertices_m[3 * t + static_cast<uint64_t>(c)];
      for (int a = 0; a < 3; ++a)
        p[a] = std::bit_cast<float>(le32(bytes, at + 12 * static_cast<std::size_t>(c) + 4 * static_cast<std::size_t>(a)));
    }
    const auto base = static_cast<int32_t>(3 * t);
    mesh.triangles[t] = {base, base + 1, base + 2};
  }
  return mesh;
}

// the words of a text one after another, with the line each is on; rest_of_line() drops the line's other words
class Words {
 public:
  explicit Words(std::string_view text) : lines_(text) {}
  bool next(std::string_view* word) {
    while (i_ >= w_.size()) {
      std::string_view line;
      if (!lines_.next(&line)) return false;
      split_words(line, &w_);
      i_ = 0;
    }
    *word = w_[i_++];
    return true;
  }
  void rest_of_line() { i_ = w_.size(); }
  int64_t line() const { return lines_.number(); }

 private:
  TextLines lines_;
  std::vector<std::string_view> w_;
  std::size_t i_ = 0;
};

Result<TriMesh> read_ascii(std::string_view bytes) {
  TriMesh mesh;
  Words in(bytes);
  std::string_view w;
  std::vector<int32_t> loop;
  int64_t facet = 0;
  int solids = 0;
  auto at = [&] { return "line " + std::to_string(in.line()) + ": "; };
  auto expect = [&](std::string_view keyword, std::string* error) {
    if (!in.next(&w)) {
      *error = "the file ends inside facet " + std::to_string(facet) + " (expected '" + std::string(keyword) + "')";
      return false;
    }
    if (!same_word(w, keyword)) {
      *error = at() + "facet " + std::to_string(facet) + ": expected '" + std::string(keyword) + "', found '" +
               std::string(w.substr(0, 40)) + "'";
      return false;
    }
    return true;
  };
  std::string error;
  while (in.next(&w)) {
    if (!same_word(w, "solid")) return Error{at() + "expected 'solid', found '" + std::string(w.substr(0, 40)) + "'"};
    in.rest_of_line();  // the solid's name
    ++solids;
    for (;;) {
      if (!in.next(&w)) return Error{"the file ends before 'endsolid' (after facet " + std::to_string(facet) + ")"};
      if (same_word(w, "endsolid")) {
        in.rest_of_line();
        break;
      }
      if (!same_word(w, "facet")) return Error{at() + "expected 'facet' or 'endsolid', found '" + std::string(w.substr(0, 40)) + "'"};
      if (!in.next(&w)) return Error{"the file ends inside facet " + std::to_string(facet)};
      if (same_word(w, "normal")) {
        for (int c = 0; c < 3; ++c) {
          double x = 0;
          if (!in.next(&w) || !parse_real(w, &x)) return Error{at() + "facet " + std::to_string(facet) + ": a normal of 3 numbers expected"};
        }
        if (!expect("outer", &error)) return Error{error};
      } else if (!same_word(w, "outer")) {
        return Error{at() + "facet " + std::to_string(facet) + ": expected 'normal' or 'outer', found '" + std::string(w.substr(0, 40)) + "'"};
      }
      if (!expect("loop", &error)) return Error{error};
      loop.clear();
      for (;;) {
        if (!in.next(&w)) return Error{"the file ends inside facet " + std::to_string(facet)};
        if (same_word(w, "endloop")) break;
        if (!same_word(w, "vertex")) return Error{at() + "facet " + std::to_string(facet) + ": expected 'vertex' or 'endloop', found '" +
                                                  std::string(w.substr(0, 40)) + "'"};
        Vec3 p;
        for (int c = 0; c < 3; ++c)
          if (!in.next(&w) || !parse_real(w, &p[c]))
            return Error{at() + "facet " + std::to_string(facet) + ": a vertex of 3 numbers expected"};
        loop.push_back(static_cast<int32_t>(mesh.vertices_m.size()));
        mesh.vertices_m.push_back(p);
      }
      if (loop.size() < 3) return Error{at() + "facet " + std::to_string(facet) + " has " + std::to_string(loop.size()) + " vertices"};
      if (!expect("endfacet", &error)) return Error{error};
      append_polygon(mesh.vertices_m, loop, &mesh.triangles);
      ++facet;
    }
  }
  if (solids == 0) return Error{"no 'solid' in the file"};
  return mesh;
}

}  // namespace

Result<TriMesh> read_stl(std::string_view bytes) {
  const uint64_t declared = bytes.size() >= 84 ? le32(bytes, 80) : 0;
  const uint64_t binary_bytes = 84 + 50 * declared;
  if (bytes.size() >= 84 && binary_bytes == bytes.size()) return read_binary(bytes, declared);
  std::size_t first = 0;
  while (first < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[first]))) ++first;
  if (bytes.size() - first >= 5 && same_word(bytes.substr(first, 5), "solid")) return read_ascii(bytes);
  if (bytes.size() < 84)
    return Error{"not an STL file: it does not start with 'solid' and is shorter than a binary STL's 84-byte header"};
  if (binary_bytes > bytes.size())
    return Error{"binary STL: the header declares " + std::to_string(declared) + " triangles (" + std::to_string(binary_bytes) +
                 " bytes), the file has " + std::to_string(bytes.size()) + " bytes"};
  // a count of 0 before whole triangles: an exporter that streamed the triangles and never wrote the count back
  if (declared == 0 && bytes.size() > 84 && (bytes.size() - 84) % 50 == 0) return read_binary(bytes, (bytes.size() - 84) / 50);
  return read_binary(bytes, declared);  // bytes after the last triangle are ignored
}

}  // namespace palpate
