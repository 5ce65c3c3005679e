#include "core/mesh_file_checks.h"

#include "core/input_file.h"
#include "core/limits.h"
#include "core/text_encoding.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace palpate {

namespace {

// smallest stored size of one PLY property: 2 characters in ASCII ("0 "), the (count) type's size in binary
double ply_property_bytes(const std::string& type, bool ascii) {
  if (ascii) return 2;
  if (type.find("64") != std::string::npos || type == "double") return 8;
  if (type.find("32") != std::string::npos || type == "int" || type == "uint" || type == "float") return 4;
  if (type.find("16") != std::string::npos || type == "short" || type == "ushort") return 2;
  return 1;
}

// One property of a PLY element: a scalar of `bytes`, or a list whose count takes `bytes` and each entry `item_bytes`.
struct PlyProperty {
  bool list = false;
  double bytes = 0;
  double item_bytes = 0;
};

struct PlyElement {
  std::string name;
  double count = 0;
  std::vector<PlyProperty> properties;
};

// A binary file read forward through a buffer: bytes are taken or skipped, never seeked back.
class ForwardReader {
 public:
  ForwardReader(const std::string& path, int64_t offset, int64_t size) : file_(path, std::ios::binary), left_(size - offset) {
    file_.seekg(offset);
  }
  // bytes not yet taken or skipped
  int64_t left() const { return left_; }
  // copies n (<= 8) bytes; false at the end of the file
  bool take(int n, unsigned char* out) {
    for (int i = 0; i < n; ++i) {
      if (pos_ == buf_.size() && !refill()) return false;
      out[i] = buf_[pos_++];
    }
    left_ -= n;
    return true;
  }
  // skips n bytes (n <= left())
  void skip(int64_t n) {
    left_ -= n;
    const int64_t in_buffer = static_cast<int64_t>(buf_.size() - pos_);
    if (n <= in_buffer) {
      pos_ += static_cast<std::size_t>(n);
      return;
    }
    file_.seekg(n - in_buffer, std::ios::cur);
    buf_.clear();
    pos_ = 0;
  }

 private:
  bool refill() {
    buf_.resize(1 << 16);
    file_.read(reinterpret_cast<char*>(buf_.data()), static_cast<std::streamsize>(buf_.size()));
    buf_.resize(static_cast<std::size_t>(std::max<std::streamsize>(file_.gcount(), 0)));
    pos_ = 0;
    return !buf_.empty();
  }

  std::ifstream file_;
  std::vector<unsigned char> buf_;
  std::size_t pos_ = 0;
  int64_t left_;
};

// Walks a binary PLY body and checks that every list's entries fit the bytes left; the first that does not is
// named ("element face 0: a list of 2147483647 entries, more than the 12 bytes left in the file"), else empty.
std::string ply_binary_lists_fit(const std::string& path, const std::vector<PlyElement>& elements, bool big_endian,
                                 int64_t body_offset, int64_t size_bytes) {
  ForwardReader in(path, body_offset, size_bytes);
  for (const PlyElement& e : elements) {
    bool has_list = false;
    int64_t fixed = 0;
    for (const PlyProperty& p : e.properties) {
      has_list = has_list || p.list;
      fixed += static_cast<int64_t>(p.bytes);
    }
    const auto count = static_cast<int64_t>(e.count);
    if (!has_list) {
      if (count * fixed > in.left()) return {};  // the size check already passed; a short file is assimp's to report
      in.skip(count * fixed);
      continue;
    }
    for (int64_t i = 0; i < count; ++i) {
      for (const PlyProperty& p : e.properties) {
        const int n = static_cast<int>(p.bytes);
        unsigned char b[8] = {};
        if (n > 8 || !in.take(n, b)) return {};  // short file: assimp reports it
        if (!p.list) continue;
        uint64_t entries = 0;
        for (int k = 0; k < n; ++k) entries |= uint64_t{b[big_endian ? n - 1 - k : k]} << (8 * k);
        // a signed count type with its sign bit set is negative: refused like a huge one
        const double need = static_cast<double>(entries) * p.item_bytes;
        if (need > static_cast<double>(in.left()))
          return "element " + e.name + " " + std::to_string(i) + ": a list of " + std::to_string(entries) +
                 " entries, more than the " + std::to_string(in.left()) + " bytes left in the file";
        in.skip(static_cast<int64_t>(need));
      }
    }
  }
  return {};
}


// The same for an ASCII PLY body: entries are blank-separated words, so a list of n entries needs at least 2n
// bytes (assimp's reader spins on a list count of 2^31 too).
std::string ply_ascii_lists_fit(const std::string& path, const std::vector<PlyElement>& elements, int64_t body_offset,
                                int64_t size_bytes) {
  ForwardReader in(path, body_offset, size_bytes);
  unsigned char c = ' ';
  // the next blank-separated word (at most 32 characters kept); false at the end of the file
  auto word = [&](std::string* w) {
    w->clear();
    while (std::isspace(c) && in.take(1, &c)) {}
    if (std::isspace(c)) return false;
    do {
      if (w->size() < 32) *w += static_cast<char>(c);
    } while (in.take(1, &c) && !std::isspace(c));
    if (!std::isspace(c)) c = ' ';  // the end of the file ends the word
    return true;
  };
  std::string w;
  for (const PlyElement& e : elements) {
    const auto count = static_cast<int64_t>(e.count);
    for (int64_t i = 0; i < count; ++i) {
      for (const PlyProperty& p : e.properties) {
        if (!word(&w)) return {};  // short file: assimp reports it
        if (!p.list) continue;
        const double entries = std::strtod(w.c_str(), nullptr);
        if (entries < 0)
          return "element " + e.name + " " + std::to_string(i) + ": a list of " + w + " entries: a count cannot be negative";
        if (!(entries >= 0) || entries * 2 > static_cast<double>(in.left()) + 1)
          return "element " + e.name + " " + std::to_string(i) + ": a list of " + w + " entries, more than the " +
                 std::to_string(in.left()) + " bytes left in the file";
        for (auto k = static_cast<int64_t>(entries); k > 0; --k)
          if (!word(&w)) return {};
      }
    }
  }
  return {};
}

// Bytes of a PLY header read to check its counts; a longer header is refused.
constexpr std::size_t kHeaderScanBytes = 65536;

// Element counts from a PLY header that the file's bytes cannot hold, else empty (the reader checks them again as
// it reads; this check stays in front of it for the fuzz target of the checks alone).
std::string implausible_counts(const std::string& path, double size_bytes) {
  std::ifstream file(path, std::ios::binary);
  std::string head(kHeaderScanBytes, '\0');
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(file.gcount()));
  // a header written as UTF-16 (or with UTF-8's mark) is checked as the text it stands for, against a file of half
  // the size for UTF-16
  const TextEncoding encoding = text_encoding(head);
  if (encoding != TextEncoding::kPlain) {
    auto text = decode_text(head, false);
    if (!text) return text.error().message;
    head = std::move(text).value();
    if (encoding != TextEncoding::kUtf8Mark) size_bytes /= 2.0;
  }
  // CR-only and CRLF line ends read as LF, so the header's lines are seen whatever the file's line ends
  const std::string raw_head = head;
  std::replace(head.begin(), head.end(), '\r', '\n');
  std::istringstream in(head);
  std::string word;
  in >> word;
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // a .ply file is read as PLY whatever its first word ("plyply" hung assimp's reader on a header with no end)
  if (word != "ply" && ext != ".ply") return {};
  // the first line that is the word end_header (assimp's reader skips a line it does not know, such as
  // "xend_header", and reads on through the binary body as header, past the end of its buffer)
  std::size_t end = std::string::npos;
  for (std::size_t at = head.find("end_header"); at != std::string::npos; at = head.find("end_header", at + 1)) {
    std::size_t line_start = at;
    while (line_start > 0 && (head[line_start - 1] == ' ' || head[line_start - 1] == '\t')) --line_start;
    const std::size_t after = at + 10;
    if ((line_start == 0 || head[line_start - 1] == '\n') &&
        (after == head.size() || std::isspace(static_cast<unsigned char>(head[after])))) {
      end = at;
      break;
    }
  }
  // assimp's PLY reader never returns on a header without end_header: it is refused here, however short
  if (end == std::string::npos)
    return "PLY header: no end_header line in the first " + std::to_string(std::min(head.size(), kHeaderScanBytes)) + " bytes";
  const bool ascii = head.find("format ascii") < end;
  const bool big_endian = head.find("format binary_big_endian") < end;
  double need_bytes = 0;
  std::vector<PlyElement> elements;
  std::ostringstream declared;
  declared << std::setprecision(15);
  std::istringstream lines(head.substr(0, end));
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string key, a, b, c;
    words >> key >> a >> b >> c;
    if (key == "element") {
      char* stop = nullptr;
      const double count = std::strtod(b.c_str(), &stop);
      if (b.empty() || *stop != '\0' || !(count >= 0) || count != std::floor(count) || count > 4294967295.0)
        return "PLY header: element " + a + " count '" + b + "' is not a whole number in [0, 4294967295]";
      elements.push_back({a, count, {}});
      declared << (declared.tellp() > 0 ? ", " : "") << a << " " << count;
    } else if (key == "property" && !elements.empty()) {
      const bool list = a == "list";
      elements.back().properties.push_back({list, ply_property_bytes(list ? b : a, ascii), list ? ply_property_bytes(c, ascii) : 0.0});
    }
  }
  for (const PlyElement& e : elements) {
    double per_element = 0;
    for (const PlyProperty& p : e.properties) per_element += p.bytes;
    need_bytes += e.count * per_element;
  }
  if (need_bytes > size_bytes)
    return "header declares " + declared.str() + ", more than the " + std::to_string(std::llround(size_bytes)) +
           "-byte file can hold";
  // every list's length must fit the bytes left (assimp's reader spins on a list of 2^31 entries)
  std::size_t body = raw_head.find('\n', end);  // "end_header\n" or "end_header\r\n"
  if (body == std::string::npos) return {};
  // a UTF-16 body is not the file's bytes: the reader checks its lists as it reads the decoded text
  if (encoding == TextEncoding::kUtf16Little || encoding == TextEncoding::kUtf16Big) return {};
  if (encoding == TextEncoding::kUtf8Mark) body += 3;
  if (ascii) return ply_ascii_lists_fit(path, elements, static_cast<int64_t>(body + 1), static_cast<int64_t>(size_bytes));
  return ply_binary_lists_fit(path, elements, big_endian, static_cast<int64_t>(body + 1), static_cast<int64_t>(size_bytes));
}

// Deepest element nesting of an XML file (first byte past blanks and a UTF-8 byte-order mark is '<'), counted
// up to limit + 1; 0 for any other file. Comments, CDATA sections, processing instructions and declarations
// (<!DOCTYPE ... [ ... ]>) do not nest; quoted attribute values may hold '>' and "/>"; <a/> opens and closes.
// *line is the line where the nesting first went past `limit`.
int xml_nesting(const std::string& path, int limit, int64_t* line) {
  std::ifstream file(path, std::ios::binary);
  std::vector<char> buf(1 << 16);
  std::size_t pos = 0, filled = 0;
  // the next byte into *c; false at the end of the file
  auto next = [&](char* c) {
    if (pos == filled) {
      file.read(buf.data(), static_cast<std::streamsize>(buf.size()));
      filled = static_cast<std::size_t>(std::max<std::streamsize>(file.gcount(), 0));
      pos = 0;
      if (filled == 0) return false;
    }
    *c = buf[pos++];
    return true;
  };
  // skip a byte-order mark and blanks; anything but '<' is not XML
  char c = 0;
  bool more = next(&c);
  if (more && c == '\xEF') {
    char b1 = 0, b2 = 0;
    if (!next(&b1) || !next(&b2) || b1 != '\xBB' || b2 != '\xBF') return 0;
    more = next(&c);
  }
  while (more && std::isspace(static_cast<unsigned char>(c))) more = next(&c);
  if (!more || c != '<') return 0;

  enum class State { kText, kOpen, kElement, kEndTag, kComment, kCData, kInstruction, kDeclaration };
  State state = State::kText;
  int depth = 0, brackets = 0;
  char quote = 0, prev = 0, prev2 = 0;
  std::string head;  // characters after "<!" that tell a comment or CDATA from a declaration
  int64_t line_no = 1;
  for (; more; more = next(&c)) {
    if (c == '\n') ++line_no;
    switch (state) {
      case State::kText:
        if (c == '<') state = State::kOpen;
        break;
      case State::kOpen:
        if (c == '/') {
          state = State::kEndTag;
        } else if (c == '?') {
          state = State::kInstruction;
        } else if (c == '!') {
          state = State::kDeclaration;
          head.clear();
          brackets = 0;
        } else {
          state = State::kElement;
          quote = 0;
        }
        break;
      case State::kElement:
        if (quote != 0) {
          if (c == quote) quote = 0;
        } else if (c == '"' || c == '\'') {
          quote = c;
        } else if (c == '>') {
          state = State::kText;
          // an element opens at the end of its tag, unless the tag closes it too (<a/>)
          if (prev != '/' && ++depth > limit) {
            *line = line_no;
            return depth;
          }
        }
        break;
      case State::kEndTag:
        if (c == '>') {
          depth = std::max(depth - 1, 0);
          state = State::kText;
        }
        break;
      case State::kInstruction:
        if (c == '>' && prev == '?') state = State::kText;
        break;
      case State::kComment:
        if (c == '>' && prev == '-' && prev2 == '-') state = State::kText;
        break;
      case State::kCData:
        if (c == '>' && prev == ']' && prev2 == ']') state = State::kText;
        break;
      case State::kDeclaration:
        if (head.size() < 7) {
          head += c;
          // the "--" or "[" that opened the section does not close it
          if (head == "--" || head == "[CDATA[") {
            state = head == "--" ? State::kComment : State::kCData;
            prev = prev2 = 0;
            continue;
          }
        }
        if (c == '[') ++brackets;
        else if (c == ']') --brackets;
        else if (c == '>' && brackets <= 0) state = State::kText;
        break;
    }
    prev2 = prev;
    prev = c;
  }
  return depth;
}

// The faces a mesh file's header declares, read before its body: a PLY's face element, an OFF's face count, a
// binary STL's triangle count (when the file's size is that count's); -1 for any other file. Each face is at least
// one triangle.
int64_t declared_faces(const std::string& path, int64_t size) {
  std::ifstream file(path, std::ios::binary);
  std::string head(4096, '\0');
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(std::max<std::streamsize>(file.gcount(), 0)));
  if (size >= 84 && head.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, head.data() + 80, sizeof n);  // little-endian, as the format and this machine
    if (84 + 50 * static_cast<int64_t>(n) == size) return n;
  }
  std::istringstream in(head);
  std::string word;
  if (!(in >> word)) return -1;
  if (word == "ply") {
    for (std::string line; std::getline(in, line);) {
      std::istringstream words(line);
      std::string key, name;
      double count = -1;
      words >> key >> name >> count;
      if (key == "end_header") break;
      if (key == "element" && name == "face" && count >= 0) return static_cast<int64_t>(std::min(count, 9.2e18));
    }
    return -1;
  }
  // OFF and its variants (COFF, NOFF, STOFF, ...); the counts may follow on the same line; # starts a comment
  if (word.size() < 3 || word.compare(word.size() - 3, 3, "OFF") != 0) return -1;
  std::vector<double> counts;
  // nOFF gives the dimension first
  const std::size_t wanted = word.size() >= 4 && word[word.size() - 4] == 'n' ? 3 : 2;
  for (std::string line; counts.size() < wanted && std::getline(in, line);) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    for (double v = 0; counts.size() < wanted && words >> v;) counts.push_back(v);
  }
  return counts.size() == wanted && counts.back() >= 0 ? static_cast<int64_t>(std::min(counts.back(), 9.2e18)) : -1;
}

}  // namespace


Status check_mesh_file(const std::string& path) {
  const std::string who = "mesh '" + path + "': ";
  // a regular file of bounded size only: never a device or a FIFO
  auto size_r = check_input_file(path, "mesh", max_mesh_file_bytes());
  if (!size_r) return size_r.error();
  const int64_t size = size_r.value();
  const std::string implausible = implausible_counts(path, static_cast<double>(size));
  if (!implausible.empty()) return make_error(who, implausible);
  // more faces than the machine's memory holds: refused from the header, before the body is read
  // (a header declaring more than the file can hold, at 2 bytes a face, is left to the reader, which says that)
  if (const int64_t faces = declared_faces(path, size); faces > max_triangles() && faces <= size / 2)
    return make_error(who, "the header declares ", std::to_string(faces), " faces, more than the ", triangle_limit_text());
  // assimp's XML readers (Collada and others) recurse once per nesting level: a deep file would overflow the stack
  int64_t deep_line = 0;
  if (const int depth = xml_nesting(path, kMaxXmlNesting, &deep_line); depth > kMaxXmlNesting)
    return make_error(who, "XML elements nested deeper than the limit of ", std::to_string(kMaxXmlNesting),
                      " levels (line ", std::to_string(deep_line), ")");
  return Ok{};
}

}  // namespace palpate
