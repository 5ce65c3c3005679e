// Limits that follow the machine's memory (core/limits.h).
#include "core/limits.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace palpate {
namespace {

// a whole number of bytes with an optional K, M or G (binary) suffix; -1 if it is not one
int64_t parse_bytes(const std::string& text) {
  if (text.empty() || text.size() > 24) return -1;
  std::size_t digits = 0;
  while (digits < text.size() && text[digits] >= '0' && text[digits] <= '9') ++digits;
  if (digits == 0 || digits > 18) return -1;
  int64_t v = std::stoll(text.substr(0, digits));
  const std::string suffix = text.substr(digits);
  const int shift = suffix.empty() ? 0 : suffix == "K" ? 10 : suffix == "M" ? 20 : suffix == "G" ? 30 : -1;
  if (shift < 0 || v > (int64_t{1} << (62 - shift))) return -1;
  return v << shift;
}

// the first line of a file as a number of bytes (a control group's limit); -1 when absent or "max"
int64_t file_bytes(const char* path) {
  std::ifstream f(path);
  std::string line;
  if (!f || !std::getline(f, line)) return -1;
  return parse_bytes(line);
}

}  // namespace

int64_t memory_bytes() {
  static const int64_t bytes = [] {
    if (const char* said = std::getenv("PALPATE_MEMORY_BYTES"); said != nullptr && said[0] != '\0') {
      const int64_t v = parse_bytes(said);
      if (v > 0) return v;
      std::fprintf(stderr, "palpate: PALPATE_MEMORY_BYTES '%.40s' is not a number of bytes (such as 8G): the machine's "
                           "memory is taken instead\n", said);
    }
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
    int64_t v = pages > 0 && page > 0 ? static_cast<int64_t>(pages) * page : int64_t{4} << 30;
    // cgroup v2, then v1 ("max" or an absent file: no limit of its own)
    for (const char* limit : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"})
      if (const int64_t c = file_bytes(limit); c > 0) v = std::min(v, c);
    return v;
  }();
  return bytes;
}

int64_t max_triangles() {
  return std::min<int64_t>(memory_bytes() / kPeakBytesPerTriangle, int64_t{1} << 29);
}

int64_t max_mesh_file_bytes() { return std::max<int64_t>(memory_bytes() / 16, int64_t{64} << 20); }

std::string triangle_limit_text() {
  char text[160];
  std::snprintf(text, sizeof text, "%lld triangles this machine's memory holds (%.1f GiB at %lld bytes a triangle)",
                static_cast<long long>(max_triangles()), static_cast<double>(memory_bytes()) / (1 << 30),
                static_cast<long long>(kPeakBytesPerTriangle));
  return text;
}

std::string limits_help() {
  char text[900];
  std::snprintf(
      text, sizeof text,
      "Limits: scene file 16 MiB (JSON nested %d deep), mesh file %lld MiB, replay log 256 MiB; %d keyframes; %lld "
      "triangles (after mesh.subdivisions; the mesh file's size and the triangles follow the memory, here %.1f GiB: "
      "PALPATE_MEMORY_BYTES); grid.levels %d (2097152 cells); XML mesh nesting %d levels; lattice %lld nodes and %lld "
      "springs (estimated from the scene and its grid before anything is built); frames 4096 x 4096 pixels; %d "
      "substeps; %d iterations; servo rate 100..20000 Hz.",
      kMaxJsonNesting, static_cast<long long>(max_mesh_file_bytes() >> 20), kMaxKeyframes,
      static_cast<long long>(max_triangles()), static_cast<double>(memory_bytes()) / (1 << 30), kMaxGridLevels,
      kMaxXmlNesting, static_cast<long long>(kMaxLatticeNodes), static_cast<long long>(kMaxLatticeSprings),
      kMaxSubsteps, kMaxIterations);
  return text;
}

}  // namespace palpate
