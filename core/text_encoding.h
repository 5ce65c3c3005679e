#pragma once
/// Text mesh files (OBJ, OFF, ASCII PLY and STL) as editors write them: a UTF-8 byte order mark (Windows tools
/// add one) or UTF-16 of either byte order with its mark. They are read as the UTF-8 text they stand for.

#include <string>
#include <string_view>

#include "core/result.h"

namespace palpate {

/// The byte order mark a file begins with.
enum class TextEncoding { kPlain, kUtf8Mark, kUtf16Little, kUtf16Big };

/// The mark at the start of bytes (kPlain: none).
TextEncoding text_encoding(std::string_view bytes);

/// bytes as UTF-8 without their mark (unchanged when plain). Errors name the byte offset of an odd trailing byte
/// or an unpaired UTF-16 surrogate. A prefix of a file (its first bytes) decodes as far as its whole characters go.
Result<std::string> decode_text(std::string_view bytes, bool whole_file = true);

}  // namespace palpate
