// The PLY reader (core/ply_reader.h).
#include "core/ply_reader.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/text_lines.h"

namespace palpate {
namespace {

// a value read from the file as the message quotes it: a whole number without decimals, otherwise as few digits as
// say it (-5, 2.5, 1e+300)
std::string ply_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

enum class Kind { kSigned, kUnsigned, kReal };

struct Type {
  int bytes = 0;  // 0: not a PLY type
  Kind kind = Kind::kSigned;
};

Type type_of(std::string_view name) {
  if (name == "char" || name == "int8") return {1, Kind::kSigned};
  if (name == "uchar" || name == "uint8") return {1, Kind::kUnsigned};
  if (name == "short" || name == "int16") return {2, Kind::kSigned};
  if (name == "ushort" || name == "uint16") return {2, Kind::kUnsigned};
  if (name == "int" || name == "int32") return {4, Kind::kSigned};
  if (name == "uint" || name == "uint32") return {4, Kind::kUnsigned};
  if (name == "float" || name == "float32") return {4, Kind::kReal};
  if (name == "double" || name == "float64") return {8, Kind::kReal};
  return {};
}

struct Property {
  std::string name;
  Type type;            // the scalar's, or a list's entries'
  Type count;           // a list's count; bytes 0 for a scalar
  bool list() const { return count.bytes > 0; }
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
  int x = -1, y = -1, z = -1;  // vertex: the properties holding the position
  int indices = -1;            // face, tristrips: the list holding the vertex indices
};

enum class Format { kAscii, kLittle, kBig };

std::string quote_word(std::string_view word) {
  std::string out(1, '\'');
  out.append(word.substr(0, 40));
  out.append(word.size() > 40 ? "...'" : "'");
  return out;
}

// reads binary scalars of the file's byte order
class BinaryBody {
 public:
  BinaryBody(std::string_view bytes, std::size_t start, bool big) : bytes_(bytes), pos_(start), big_(big) {}
  std::size_t left() const { return bytes_.size() - pos_; }
  void skip(std::size_t n) { pos_ += n; }
  // the next value of type t (which fits in what is left)
  double value(Type t) {
    unsigned char b[8] = {};
    for (int k = 0; k < t.bytes; ++k)
      b[big_ ? t.bytes - 1 - k : k] = static_cast<unsigned char>(bytes_[pos_ + static_cast<std::size_t>(k)]);
    pos_ += static_cast<std::size_t>(t.bytes);
    uint64_t u = 0;
    for (int k = t.bytes - 1; k >= 0; --k) u = (u << 8) | b[k];
    if (t.kind == Kind::kReal) {
      if (t.bytes == 4) return std::bit_cast<float>(static_cast<uint32_t>(u));
      return std::bit_cast<double>(u);
    }
    if (t.kind == Kind::kUnsigned) return static_cast<double>(u);
    const int shift = 64 - 8 * t.bytes;
    return static_cast<double>(static_cast<int64_t>(u << shift) >> shift);
  }

 private:
  std::string_view bytes_;
  std::size_t pos_;
  bool big_;
};

// polygons as read: sizes and the indices one after another
struct Polygons {
  std::vector<uint32_t> sizes;
  std::vector<int64_t> indices;
  bool strips = false;  // a tristrips element: one list of strips with -1 between them
};

}  // namespace

Result<TriMesh> read_ply(std::string_view bytes) {
  TextLines lines(bytes);
  std::string_view line;
  std::vector<std::string_view> w;
  if (!lines.next(&line) || (split_words(line, &w), w.size() != 1 || w[0] != "ply"))
    return Error{"line 1: a PLY file starts with a line 'ply'"};
  Format format = Format::kAscii;
  bool have_format = false;
  std::vector<Element> elements;
  bool ended = false;
  while (!ended && lines.next(&line)) {
    split_words(line, &w);
    const std::string at = "line " + std::to_string(lines.number()) + ": ";
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      ended = true;
    } else if (w[0] == "format") {
      if (w.size() < 3 || w[2] != "1.0") return Error{at + "PLY header: expected 'format ascii|binary_little_endian|binary_big_endian 1.0'"};
      if (w[1] == "ascii") format = Format::kAscii;
      else if (w[1] == "binary_little_endian") format = Format::kLittle;
      else if (w[1] == "binary_big_endian") format = Format::kBig;
      else return Error{at + "PLY header: unknown format " + quote_word(w[1])};
      have_format = true;
    } else if (w[0] == "element") {
      int64_t count = 0;
      if (w.size() < 3 || !parse_integer(w[2], &count) || count < 0 || count > 4294967295LL)
        return Error{at + "PLY header: element " + (w.size() > 1 ? std::string(w[1]) : "") + " count " +
                     (w.size() > 2 ? quote_word(w[2]) : "(none)") + " is not a whole number in [0, 4294967295]"};
      elements.push_back({std::string(w[1]), static_cast<uint64_t>(count), {}});
    } else if (w[0] == "property") {
      if (elements.empty()) return Error{at + "PLY header: a property before any element"};
      Property p;
      if (w.size() >= 5 && w[1] == "list") {
        p.count = type_of(w[2]);
        p.type = type_of(w[3]);
        p.name = std::string(w[4]);
        if (p.count.bytes == 0 || p.count.kind == Kind::kReal || p.type.bytes == 0)
          return Error{at + "PLY header: list types " + quote_word(w[2]) + " " + quote_word(w[3]) + " are not an integer count type and a PLY type"};
      } else if (w.size() >= 3 && w[1] != "list") {
        p.type = type_of(w[1]);
        p.name = std::string(w[2]);
        if (p.type.bytes == 0) return Error{at + "PLY header: unknown property type " + quote_word(w[1])};
      } else {
        return Error{at + "PLY header: expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'"};
      }
      elements.back().properties.push_back(p);
    }
    // any other line (Blender 2.4 wrote "Created by ..." without "comment") is skipped, as other readers do
  }
  if (!ended) return Error{"PLY header: no end_header line"};
  if (!have_format) return Error{"PLY header: no format line"};

  // which properties carry the surface
  Element* vertex = nullptr;
  for (Element& e : elements) {
    for (int k = 0; k < static_cast<int>(e.properties.size()); ++k) {
      const Property& p = e.properties[static_cast<std::size_t>(k)];
      if (!p.list() && p.name == "x") e.x = k;
      if (!p.list() && p.name == "y") e.y = k;
      if (!p.list() && p.name == "z") e.z = k;
      if (p.list() && (p.name == "vertex_indices" || p.name == "vertex_index")) e.indices = k;
    }
    if (e.name == "vertex" && vertex == nullptr) vertex = &e;
    if ((e.name == "face" || e.name == "tristrips") && e.indices < 0) {
      int lists = 0;
      for (int k = 0; k < static_cast<int>(e.properties.size()); ++k)
        if (e.properties[static_cast<std::size_t>(k)].list()) {
          ++lists;
          e.indices = k;
        }
      if (lists != 1) e.indices = -1;
    }
  }
  if (vertex == nullptr) return Error{"PLY header: no vertex element"};
  if (vertex->x < 0 || vertex->y < 0 || vertex->z < 0) return Error{"PLY header: element vertex lacks one of the properties x, y, z"};
  if (vertex->count > static_cast<uint64_t>(INT32_MAX)) return Error{"PLY header: more than 2147483647 vertices"};
  // the least a body can take: every element's fixed part (ASCII: a digit and a blank a value)
  double least = 0;
  for (const Element& e : elements) {
    double per = 0;
    for (const Property& p : e.properties) per += format == Format::kAscii ? 2.0 : (p.list() ? p.count.bytes : p.type.bytes);
    least += per * static_cast<double>(e.count);
  }
  const std::size_t body = lines.offset();
  if (least > static_cast<double>(bytes.size() - std::min(body, bytes.size()))) {
    std::string declared;
    for (const Element& e : elements) declared += (declared.empty() ? "" : ", ") + e.name + " " + std::to_string(e.count);
    return Error{"header declares " + declared + ", more than the " + std::to_string(bytes.size()) + "-byte file can hold"};
  }

  TriMesh mesh;
  mesh.vertices_m.resize(static_cast<std::size_t>(vertex->count));
  std::vector<Polygons> faces;
  std::vector<double> values;  // one instance's scalars, lists' entries after them
  BinaryBody bin(bytes, body, format == Format::kBig);
  TextLines text(bytes, body, lines.number() + 1);
  for (Element& e : elements) {
    const bool is_vertex = &e == vertex;
    const bool is_face = (e.name == "face" || e.name == "tristrips") && e.indices >= 0;
    Polygons* polys = nullptr;
    if (is_face) {
      faces.emplace_back();
      polys = &faces.back();
      polys->strips = e.name == "tristrips";
      // room for triangles, within what the file's bytes can hold
      const std::size_t most = bytes.size() / 4;
      polys->sizes.reserve(std::min(static_cast<std::size_t>(e.count), most));
      polys->indices.reserve(std::min(static_cast<std::size_t>(e.count) * 3, most));
    }
    for (uint64_t i = 0; i < e.count; ++i) {
      // (the element's name and the line are made into text only for a message: a model has millions of elements)
      auto who = [&e, i] { return "element " + e.name + " " + std::to_string(i); };
      std::size_t word = 0;
      if (format == Format::kAscii) {
        do {
          if (!text.next(&line)) return Error{"the file ends before " + who()};
          split_words(line, &w);
        } while (w.empty());
      }
      auto where = [&] { return format == Format::kAscii ? "line " + std::to_string(text.number()) + ": " : std::string(); };
      // the next value of type t: false (with *error) when the file or the line has no more
      std::string error;
      auto next = [&](Type t, double* out) {
        if (format != Format::kAscii) {
          if (bin.left() < static_cast<std::size_t>(t.bytes)) {
            error = "the file ends inside " + who();
            return false;
          }
          *out = bin.value(t);
          return true;
        }
        if (word >= w.size()) {
          error = where() + who() + ": its line holds " + std::to_string(w.size()) + " values, fewer than its properties need";
          return false;
        }
        if (!parse_real(w[word], out)) {
          error = where() + who() + ": " + quote_word(w[word]) + " is not a number";
          return false;
        }
        ++word;
        return true;
      };
      for (int k = 0; k < static_cast<int>(e.properties.size()); ++k) {
        const Property& p = e.properties[static_cast<std::size_t>(k)];
        double v = 0;
        if (!p.list()) {
          if (!next(p.type, &v)) return Error{error};
          if (is_vertex && (k == e.x || k == e.y || k == e.z))
            mesh.vertices_m[static_cast<std::size_t>(i)][k == e.x ? 0 : k == e.y ? 1 : 2] = v;
          continue;
        }
        if (!next(p.count, &v)) return Error{error};
        // entries fit the bytes left (binary) or the words left on the line (ASCII) before any is kept
        const double room = format == Format::kAscii ? static_cast<double>(w.size() - word)
                                                     : static_cast<double>(bin.left()) / p.type.bytes;
        if (!(v >= 0) || v != std::floor(v) || v > room) {
          if (v < 0)
            return Error{where() + who() + ": a list of " + ply_number(v) + " entries: a count cannot be negative"};
          if (format != Format::kAscii)
            return Error{who() + ": a list of " + std::to_string(static_cast<int64_t>(v)) + " entries, more than the " +
                         std::to_string(bin.left()) + " bytes left in the file"};
          return Error{where() + who() + ": a list of " + quote_word(w[word - 1]) + " entries, its line holds " +
                       std::to_string(w.size() - word) + " more values"};
        }
        const auto n = static_cast<std::size_t>(v);
        const bool keep = is_face && k == e.indices;
        for (std::size_t m = 0; m < n; ++m) {
          if (!next(p.type, &v)) return Error{error};
          if (!keep) continue;
          if (v != std::floor(v) || !(v < 4294967296.0))
            return Error{where() + who() + ": vertex index " + ply_number(v) + " is not a whole number"};
          if (v < 0 && !(v == -1 && polys->strips))
            return Error{where() + who() + ": vertex index " + ply_number(v) + " is negative (indices count from 0)"};
          const auto index = static_cast<int64_t>(v);
          if ((index < 0 && !polys->strips) || index >= static_cast<int64_t>(vertex->count))
            return Error{where() + (polys->strips ? who() : "face " + std::to_string(i)) + " vertex index " + std::to_string(index) +
                         " is beyond the vertex list (size " + std::to_string(vertex->count) + ")"};
          polys->indices.push_back(index);
        }
        if (keep) {
          if (n == 0 && !polys->strips) return Error{where() + "face " + std::to_string(i) + " has no vertex indices"};
          polys->sizes.push_back(static_cast<uint32_t>(n));
        }
      }
    }
  }
  // polygons once every vertex is known (a face element may come before the vertex element)
  std::vector<int32_t> polygon;
  std::size_t polygons = 0;
  for (const Polygons& polys : faces) polygons += polys.strips ? 0 : polys.sizes.size();
  mesh.triangles.reserve(polygons);
  for (const Polygons& polys : faces) {
    std::size_t start = 0;
    for (uint32_t n : polys.sizes) {
      if (!polys.strips) {
        polygon.assign(polys.indices.begin() + static_cast<std::ptrdiff_t>(start),
                       polys.indices.begin() + static_cast<std::ptrdiff_t>(start + n));
        append_polygon(mesh.vertices_m, polygon, &mesh.triangles);
      } else {
        // a strip: each index after the second makes a triangle with the two before it, alternately wound
        int run = 0;
        for (std::size_t m = start; m < start + n; ++m) {
          const int64_t id = polys.indices[m];
          if (id < 0) {
            run = 0;
            continue;
          }
          if (++run >= 3) {
            const auto a = static_cast<int32_t>(polys.indices[m - 2]), b = static_cast<int32_t>(polys.indices[m - 1]);
            if (run % 2 == 1) mesh.triangles.push_back({a, b, static_cast<int32_t>(id)});
            else mesh.triangles.push_back({b, a, static_cast<int32_t>(id)});
          }
        }
      }
      start += n;
    }
  }
  return mesh;
}

}  // namespace palpate
