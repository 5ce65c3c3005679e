#include "tools/bench/bench_mesh.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/mesh_io.h"
#include "core/stats.h"

namespace palpate {

Result<std::string> run_bench_mesh(const BenchMeshOptions& options) {
  std::string table = "file                                   vertices  triangles  way           median_ms    min_ms\n";
  for (const std::string& file : options.files) {
    std::vector<double> ms[2];  // [0] child process, [1] in-process
    std::size_t counts[2][2] = {};
    for (int rep = 0; rep < options.repetitions; ++rep) {
      for (int way = 0; way < 2; ++way) {
        MeshReadOptions ro;
        ro.isolation = way == 0 ? MeshReaderIsolation::child_process : MeshReaderIsolation::in_process;
        const auto start = std::chrono::steady_clock::now();
        const auto mesh = load_mesh(file, ro);
        ms[way].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        if (!mesh) return mesh.error();
        counts[way][0] = mesh.value().num_vertices();
        counts[way][1] = mesh.value().num_triangles();
      }
    }
    if (counts[0][0] != counts[1][0] || counts[0][1] != counts[1][1])
      return make_error("bench mesh: '", file, "' loads differently in a child process and in this process");
    static const char* const kWays[2] = {"child_process", "in_process"};
    for (int way = 0; way < 2; ++way) {
      char line[512];
      std::snprintf(line, sizeof line, "%-38s %9zu %10zu  %-13s %9.1f %9.1f\n", file.c_str(), counts[way][0],
                    counts[way][1], kWays[way], percentile(ms[way], 0.5), percentile(ms[way], 0.0));
      table += line;
    }
    char ratio[160];
    std::snprintf(ratio, sizeof ratio, "%-38s child/in-process median: %.3f\n", "",
                  percentile(ms[0], 0.5) / percentile(ms[1], 0.5));
    table += ratio;
  }
  return table;
}

}  // namespace palpate
