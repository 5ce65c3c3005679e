#pragma once
// The options a test records with: a fresh output folder of its own, nothing printed, frames drawn unless told not
// to. One place, so a recording test says only what it changes.

#include <string>

#include "runtime/record/recorder.h"
#include "support/fixtures.h"

namespace palpate::test {

inline RecordOptions quiet_options(const std::string& tag, bool render = true) {
  RecordOptions opt;
  opt.out_dir = fresh_dir(tag);
  opt.quiet = true;
  opt.render = render;
  return opt;
}

}  // namespace palpate::test
