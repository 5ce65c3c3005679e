#pragma once
/// Subcommand: one `palpate` subcommand as main sees it — the CLI11 app it registered its own options on, and
/// what to run when the command line chose it. Each add_*_command() owns its options (captured by `run`).

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace palpate {

/// A registered subcommand. Plain data; `run` returns the process's exit status.
struct Subcommand {
  CLI::App* app = nullptr;   ///< the subcommand (parsed when *app is true)
  std::function<int()> run;  ///< runs it with the parsed options
};

/// The path of the running program as it was invoked (argv[0]), for commands printed to be pasted; set once by
/// main, "palpate" until then.
inline std::string& invoked_program() {
  static std::string program = "palpate";
  return program;
}

}  // namespace palpate
