#pragma once
// The one temporary folder of a test process: every file a test writes goes under it, and it is removed
// with its contents when the process exits, so a test run leaves nothing in the system temp folder.

#include <string>

namespace palpate::test {

/// A folder made for this process under $TMPDIR (or /tmp) on first use, removed at exit. Thread: any.
const std::string& temp_root();

/// temp_root()/prefix + name: a test file's path, its prefix naming the test file that writes it. Thread: any.
std::string temp_path(const std::string& prefix, const std::string& name);

}  // namespace palpate::test
