#pragma once
/// `palpate bench ...`: the benchmarks' subcommands and their options.

#include <CLI/CLI.hpp>

#include "tools/commands/subcommand.h"

namespace palpate {

/// Registers `bench` and its subcommands (loop, force, sim, scale, model, png, mesh) on `app`.
Subcommand add_bench_command(CLI::App& app);

}  // namespace palpate
