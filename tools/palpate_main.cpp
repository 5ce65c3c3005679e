// palpate: record touch/pull/cut demos headless, make their videos, inspect meshes, write scenes, benchmark.

#include <csignal>
#include <cstdio>
#include <exception>
#include <new>

#include <CLI/CLI.hpp>

#include "core/limits.h"
#include "tools/commands/bench_cli.h"
#include "tools/commands/cli_checks.h"
#include "tools/commands/record_cli.h"
#include "tools/commands/subcommand.h"
#include "tools/commands/sweep_command.h"
#include "tools/commands/tool_cli.h"

int main(int argc, char** argv) {
  // a file-size limit (ulimit -f) fails the write that crosses it with EFBIG, reported against that file like a
  // full disk, instead of killing the process with SIGXFSZ halfway through its outputs
  std::signal(SIGXFSZ, SIG_IGN);
  if (argc > 0 && argv[0] != nullptr && *argv[0] != '\0') palpate::invoked_program() = argv[0];
  CLI::App app{"palpate: feel and deform 3D models through a haptic device; headless recordings and loop-rate figures"};
  palpate::prefix_usage_errors(app, "palpate");
  app.require_subcommand(1);
  const palpate::Subcommand commands[] = {palpate::add_record_command(app), palpate::add_video_command(app),
                                          palpate::add_info_command(app), palpate::add_scene_command(app),
                                          palpate::add_bench_command(app),
                                          palpate::add_sweep_command(app)};
  app.footer(palpate::limits_help());  // after the subcommands, which would copy it: printed here only
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  // the commands report their own failures; out of memory (or a failure no command foresaw) is still a line and
  // an exit status, never an abort
  try {
    for (const auto& c : commands)
      if (*c.app) return c.run();
  } catch (const std::bad_alloc&) {
    std::fputs("palpate: out of memory\n", stderr);
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "palpate: %s\n", e.what());
    return 1;
  }
  return 2;
}
