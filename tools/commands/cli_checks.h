#pragma once
/// Command-line checks shared by palpate and palpate-device.

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace palpate {

/// A number in [lo, hi] that is finite: CLI::Range lets "nan" through (every comparison with NaN is false).
inline CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v)) return "Value " + text + " is not a number";
        if (!std::isfinite(v) || v < lo || v > hi)
          return "Value " + text + " not in range [" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]";
        return {};
      },
      "FLOAT in [" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]");
}

/// The numbers of a list option given as text: "none" or "" alone is the empty list; each other item a finite number
/// in [lo, hi]. False, with `error` naming the option and the item, otherwise.
inline bool parse_number_list(const std::vector<std::string>& items, const char* option, double lo, double hi,
                              std::vector<double>* out, std::string* error) {
  out->clear();
  if (items.size() == 1 && (items[0].empty() || items[0] == "none")) return true;
  for (const std::string& item : items) {
    double v = 0.0;
    if (!CLI::detail::lexical_cast(item, v) || !std::isfinite(v) || v < lo || v > hi) {
      *error = std::string(option) + ": '" + item + "' is not a number in [" + CLI::detail::to_string(lo) + ", " +
               CLI::detail::to_string(hi) + "] (none: " + option + " none)";
      return false;
    }
    out->push_back(v);
  }
  return true;
}

/// A default input named relative to the repository ("scenes/bunny_pull.json"): taken from the current folder when
/// it is there, else from the nearest folder above the program that holds it (build/bin/palpate lies two below the
/// repository root), so the commands' defaults work from any folder. Unchanged when found nowhere: the loader's
/// error names it.
inline std::string locate_default(const std::string& rel) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(rel, ec)) return rel;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return rel;
  for (fs::path d = exe.parent_path(); !d.empty(); d = d.parent_path()) {
    if (fs::exists(d / rel, ec)) return (d / rel).string();
    if (d == d.root_path()) break;
  }
  return rel;
}

/// Usage errors in the same shape as every other error: "<program>: <what>", then where to look. Set on the top
/// app before any subcommand is added (subcommands copy it when they are made).
inline void prefix_usage_errors(CLI::App& app, std::string program) {
  app.failure_message([program](const CLI::App*, const CLI::Error& e) {
    return program + ": " + e.what() + "\nRun with --help for more information.\n";
  });
}

}  // namespace palpate
