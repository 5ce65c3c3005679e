#include "runtime/record/frame_files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace palpate {
namespace fs = std::filesystem;

Result<std::vector<FrameFile>> list_frame_files(const std::string& frames_dir) {
  std::error_code ec;
  std::vector<FrameFile> files;
  for (const auto& e : fs::directory_iterator(frames_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".png" || name.rfind("frame_", 0) != 0) continue;
    const std::string digits = name.substr(6, name.size() - 6 - 4);
    if (digits.empty() || digits.size() > 10 || digits.find_first_not_of("0123456789") != std::string::npos ||
        std::stoll(digits) > kMaxFrameNumber)
      return make_error("frame '", e.path().string(), "': the name is not frame_N.png with N a number from 0 to ",
                        std::to_string(kMaxFrameNumber));
    // a FIFO would block the reader for ever, a device or a folder is no frame; a link to a file is followed
    std::error_code sec;
    if (!fs::is_regular_file(e.path(), sec))
      return make_error("frame '", e.path().string(), "': not a regular file");
    files.push_back(FrameFile{std::stoll(digits), e.path().string()});
  }
  if (ec) return make_error("cannot read '", frames_dir, "': ", ec.message());
  if (files.empty()) return make_error("no frame_*.png in '", frames_dir, "'");
  std::sort(files.begin(), files.end(), [](const FrameFile& a, const FrameFile& b) { return a.number < b.number; });
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (files[i].number == static_cast<int64_t>(i)) continue;
    if (i > 0 && files[i].number == files[i - 1].number)
      return make_error("frame '", files[i].path, "': frame ", std::to_string(files[i].number), " also is '",
                        files[i - 1].path, "'");
    return make_error("frame ", std::to_string(i), " is missing from '", frames_dir, "' (", std::to_string(files.size()),
                      " files, frame_N.png must run from N = 0 without a gap; the next one is '", files[i].path, "')");
  }
  return files;
}

Result<std::pair<int64_t, int64_t>> png_size(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return make_error("png '", path, "': ", std::strerror(errno));
  unsigned char h[24] = {};
  ssize_t got = 0;
  while (got < 24) {
    const ssize_t n = ::read(fd, h + got, static_cast<std::size_t>(24 - got));
    if (n <= 0) break;
    got += n;
  }
  ::close(fd);
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (got < 24 || std::memcmp(h, kSignature, 8) != 0 || std::memcmp(h + 12, "IHDR", 4) != 0)
    return make_error("png '", path, "': not a PNG file (no signature and IHDR)");
  const auto be32 = [](const unsigned char* p) {
    return (int64_t{p[0]} << 24) | (int64_t{p[1]} << 16) | (int64_t{p[2]} << 8) | int64_t{p[3]};
  };
  return std::pair<int64_t, int64_t>{be32(h + 16), be32(h + 20)};
}

}  // namespace palpate
