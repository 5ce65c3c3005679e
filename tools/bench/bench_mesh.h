#pragma once
/// `palpate bench mesh`: loading mesh files with the reader in a forked child (what palpate does) against the
/// reader in this process, alternately, side by side: median and fastest wall time per way, and their ratio.

#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// What to load.
struct BenchMeshOptions {
  std::vector<std::string> files;  ///< mesh files, each a valid one (the in-process way has no crash guard)
  int repetitions = 5;             ///< loads per way and file, the two ways alternating
};

/// Runs the loads and returns the table (errors name the file).
Result<std::string> run_bench_mesh(const BenchMeshOptions& options);

}  // namespace palpate
