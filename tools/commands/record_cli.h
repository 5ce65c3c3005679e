#pragma once
/// `palpate record`: its options, and the run from the record plan to the printed list of outputs.

#include <CLI/CLI.hpp>

#include "tools/commands/subcommand.h"

namespace palpate {

/// Registers `record` and its options on `app`.
Subcommand add_record_command(CLI::App& app);

}  // namespace palpate
