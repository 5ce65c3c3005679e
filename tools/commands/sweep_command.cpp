#include "tools/commands/sweep_command.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace palpate {
namespace {

struct SweepArgs {
  std::string spec;
  std::string out;
  std::string scheduler;
  int workers = 0;
  bool quiet = false;
};

// the interpreter and package folder the build made the module for (python/CMakeLists.txt); empty without it
#ifdef PALPATE_PYTHON
constexpr const char* kPython = PALPATE_PYTHON;
constexpr const char* kPythonDir = PALPATE_PYTHON_DIR;
#else
constexpr const char* kPython = "";
constexpr const char* kPythonDir = "";
#endif

int run_sweep(const SweepArgs& a) {
  if (*kPython == '\0') {
    std::fprintf(stderr, "palpate: sweep runs in the Python module, which this build has not got (it needs Debian's "
                         "pybind11-dev and python3-dev: scripts/install_deps.sh, then scripts/build.sh)\n");
    return 1;
  }
  std::vector<std::string> args{kPython, "-m", "palpate", "sweep", a.spec};
  if (!a.out.empty()) args.insert(args.end(), {"--out", a.out});
  if (!a.scheduler.empty()) args.insert(args.end(), {"--scheduler", a.scheduler});
  if (a.workers > 0) args.insert(args.end(), {"--workers", std::to_string(a.workers)});
  if (a.quiet) args.emplace_back("-q");
  // the module this program was built with comes first on the interpreter's path
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = std::string(kPythonDir) + (old != nullptr && *old != '\0' ? ":" + std::string(old) : "");
  ::setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<char*> argv;
  for (std::string& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  ::execv(kPython, argv.data());
  std::fprintf(stderr, "palpate: sweep: cannot run '%s': %s\n", kPython, std::strerror(errno));
  return 1;
}

}  // namespace

Subcommand add_sweep_command(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  auto* c = app.add_subcommand("sweep", "Run many recordings from one spec (scene overrides x models x modes) "
                                        "into one table, locally or on a Dask cluster (docs/python.md)");
  c->add_option("spec", a->spec, "The sweep's JSON spec")->required();
  c->add_option("--out,-o", a->out, "The sweep's folder: runs/<run>/ and sweep.csv (default: out/sweep_<spec name>); "
                                    "runs already finished there are skipped");
  c->add_option("--scheduler", a->scheduler, "A Dask scheduler's address, e.g. tcp://HOST:8786 (`dask scheduler` "
                                             "on one machine, `dask worker ADDR` on the others); default: local");
  c->add_option("--workers", a->workers, "Local processes (default: the cores)")->check(CLI::Range(1, 1024));
  c->add_flag("--quiet,-q", a->quiet, "No progress lines");
  return {c, [a] { return run_sweep(*a); }};
}

}  // namespace palpate
