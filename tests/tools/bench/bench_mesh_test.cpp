// `palpate bench mesh` through the command: the reader in a child process and in this process each give the
// mesh's own vertex and triangle counts (counted here from the OBJ's lines), one row per way with the ratio of
// their medians after them; a file that cannot be read is an error naming it, with nothing printed as a table.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/read_file.h"

namespace palpate {
namespace {

using test::CliRun;
using test::palpate;

// Vertices ("v" lines) and triangles (a face of n corners makes n - 2) of an OBJ file.
void count_obj(const std::string& path, long long* vertices, long long* triangles) {
  std::istringstream lines(test::read_file(path));
  *vertices = *triangles = 0;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string key, corner;
    words >> key;
    if (key == "v") ++*vertices;
    if (key != "f") continue;
    int corners = 0;
    while (words >> corner) ++corners;
    *triangles += corners - 2;
  }
}

// One row of the table: file, vertices, triangles, way, median ms, fastest ms.
struct Row {
  std::string file, way;
  long long vertices = -1, triangles = -1;
  double median_ms = -1.0, min_ms = -1.0;
};

TEST(BenchMesh, BothReadersGiveTheFilesCountsAndTheRatioOfTheirMedians) {
  const std::string file = test::source_path("scenes/bunny.obj");
  long long vertices = 0, triangles = 0;
  count_obj(file, &vertices, &triangles);
  ASSERT_GT(triangles, 0);

  const CliRun r = palpate("bench mesh " + file + " --reps 2");
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream lines(r.out);
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("file ", 0), 0u) << r.out;
  std::vector<Row> rows;
  double ratio = -1.0;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    const std::string prefix = "child/in-process median:";
    if (const std::size_t at = line.find(prefix); at != std::string::npos) {
      ratio = std::stod(line.substr(at + prefix.size()));
      continue;
    }
    Row row;
    words >> row.file >> row.vertices >> row.triangles >> row.way >> row.median_ms >> row.min_ms;
    ASSERT_FALSE(words.fail()) << "unreadable row: " << line;
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), 2u) << r.out;
  EXPECT_EQ(rows[0].way, "child_process");
  EXPECT_EQ(rows[1].way, "in_process");
  for (const Row& row : rows) {
    EXPECT_EQ(row.file, file);
    EXPECT_EQ(row.vertices, vertices) << row.way;
    EXPECT_EQ(row.triangles, triangles) << row.way;
    EXPECT_GT(row.min_ms, 0.0) << row.way;
    EXPECT_LE(row.min_ms, row.median_ms) << row.way;
  }
  // the ratio is of the two medians (printed to 0.1 ms: the check allows that rounding)
  ASSERT_GT(ratio, 0.0) << r.out;
  EXPECT_LE(std::abs(ratio * rows[1].median_ms - rows[0].median_ms), 0.05 * (1.0 + ratio) + 0.0005 * rows[1].median_ms)
      << r.out;
}

TEST(BenchMesh, AFileThatCannotBeReadIsAnErrorNamingIt) {
  const std::string missing = test::source_path("scenes/no_such_mesh.obj");
  const CliRun r = palpate("bench mesh " + test::source_path("scenes/bunny.obj") + " " + missing + " --reps 1");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_EQ(r.out, "palpate: mesh '" + missing + "': file not found\n");
}

}  // namespace
}  // namespace palpate
