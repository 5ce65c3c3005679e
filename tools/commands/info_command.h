#pragma once
/// `palpate info`: mesh statistics and the grid hierarchy per level.

#include <string>

namespace palpate {

/// Prints counts, the box and per-level occupancy of the mesh at path (JSON when json is set).
/// Returns the process exit code (0, or 1 with a one-line error on stderr).
int run_info(const std::string& path, int levels, bool json);

}  // namespace palpate
