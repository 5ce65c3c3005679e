#include "core/text_encoding.h"

#include <cstdint>

namespace palpate {

TextEncoding text_encoding(std::string_view bytes) {
  auto at = [&](std::size_t i) { return static_cast<unsigned char>(bytes[i]); };
  if (bytes.size() >= 3 && at(0) == 0xEF && at(1) == 0xBB && at(2) == 0xBF) return TextEncoding::kUtf8Mark;
  if (bytes.size() >= 2 && at(0) == 0xFF && at(1) == 0xFE) return TextEncoding::kUtf16Little;
  if (bytes.size() >= 2 && at(0) == 0xFE && at(1) == 0xFF) return TextEncoding::kUtf16Big;
  return TextEncoding::kPlain;
}

namespace {

void append_utf8(uint32_t c, std::string* out) {
  if (c < 0x80) {
    out->push_back(static_cast<char>(c));
  } else if (c < 0x800) {
    out->push_back(static_cast<char>(0xC0 | (c >> 6)));
    out->push_back(static_cast<char>(0x80 | (c & 0x3F)));
  } else if (c < 0x10000) {
    out->push_back(static_cast<char>(0xE0 | (c >> 12)));
    out->push_back(static_cast<char>(0x80 | ((c >> 6) & 0x3F)));
    out->push_back(static_cast<char>(0x80 | (c & 0x3F)));
  } else {
    out->push_back(static_cast<char>(0xF0 | (c >> 18)));
    out->push_back(static_cast<char>(0x80 | ((c >> 12) & 0x3F)));
    out->push_back(static_cast<char>(0x80 | ((c >> 6) & 0x3F)));
    out->push_back(static_cast<char>(0x80 | (c & 0x3F)));
  }
}

}  // namespace

Result<std::string> decode_text(std::string_view bytes, bool whole_file) {
  const TextEncoding enc = text_encoding(bytes);
  if (enc == TextEncoding::kPlain) return std::string(bytes);
  if (enc == TextEncoding::kUtf8Mark) return std::string(bytes.substr(3));
  const bool little = enc == TextEncoding::kUtf16Little;
  auto unit = [&](std::size_t i) -> uint32_t {
    const auto lo = static_cast<unsigned char>(bytes[little ? i : i + 1]);
    const auto hi = static_cast<unsigned char>(bytes[little ? i + 1 : i]);
    return static_cast<uint32_t>(hi) << 8 | lo;
  };
  std::string out;
  out.reserve(bytes.size() / 2);
  std::size_t i = 2;
  for (; i + 1 < bytes.size(); i += 2) {
    const uint32_t u = unit(i);
    if (u >= 0xD800 && u < 0xDC00) {
      // a high surrogate and the low one after it make one character beyond the 16-bit plane
      if (i + 3 >= bytes.size()) {
        if (!whole_file) break;
        return make_error("UTF-16 text: a high surrogate at byte ", std::to_string(i), " ends the file");
      }
      const uint32_t low = unit(i + 2);
      if (low < 0xDC00 || low >= 0xE000)
        return make_error("UTF-16 text: the high surrogate at byte ", std::to_string(i), " has no low surrogate after it");
      append_utf8(0x10000 + ((u - 0xD800) << 10) + (low - 0xDC00), &out);
      i += 2;
    } else if (u >= 0xDC00 && u < 0xE000) {
      return make_error("UTF-16 text: a low surrogate at byte ", std::to_string(i), " with no high surrogate before it");
    } else {
      append_utf8(u, &out);
    }
  }
  if (whole_file && i < bytes.size())
    return make_error("UTF-16 text of an odd number of bytes (", std::to_string(bytes.size()), "): its last byte is half a character");
  return out;
}

}  // namespace palpate
