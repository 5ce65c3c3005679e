#pragma once
/// `palpate sweep SPEC.json`: many recordings from one spec, run by the Python module's palpate.sweep (one
/// implementation for the command line and Python: a local process pool, or a Dask cluster with --scheduler).

#include <CLI/CLI.hpp>

#include "tools/commands/subcommand.h"

namespace palpate {

/// Registers `sweep` and its options on `app`.
Subcommand add_sweep_command(CLI::App& app);

}  // namespace palpate
