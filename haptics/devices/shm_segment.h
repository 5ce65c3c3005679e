#pragma once
/// ShmSegment: a mapped palpate_shim_segment (haptics/shim/palpate_shim.h) — served by the device process,
/// connected to by the sim — with every check a peer's segment needs (owner, mode, size, magic, version), and a
/// guard that survives the segment being truncated under the mapping (SIGBUS) instead of dying of it.

#include <string>

#include "core/result.h"
#include "haptics/shim/palpate_shim.h"

namespace palpate {

/// Owns one mapping of a shim segment. Move-only; unmaps on destruction (the name stays until unlink()).
class ShmSegment {
 public:
  ShmSegment() = default;
  ~ShmSegment();
  ShmSegment(ShmSegment&& o) noexcept;
  ShmSegment& operator=(ShmSegment&& o) noexcept;
  ShmSegment(const ShmSegment&) = delete;
  ShmSegment& operator=(const ShmSegment&) = delete;

  /// Device side: creates "/palpate-NAME" (mode 0600), or re-attaches to a compatible one an earlier device
  /// process of this user left (repairs a half-written pose, bumps the epoch); publishes specs, then magic.
  /// Refuses a segment whose device process still lives and has not stopped ("already served by device process
  /// 1234"): a seqlock has a single writer.
  static Result<ShmSegment> serve(const std::string& name, const palpate_shim_specs& specs);
  /// Sim side: opens "/palpate-NAME", waiting up to timeout_s for it to exist and be published; refuses a
  /// segment of another user, one others may access, or one whose size, magic or version differ from this build's.
  static Result<ShmSegment> connect(const std::string& name, double timeout_s);
  /// Removes the name (mappings stay valid). Returns false when it did not exist.
  static bool unlink(const std::string& name);
  /// Checks a link name: 1..PALPATE_SHIM_NAME_MAX of [A-Za-z0-9_.-].
  static Status check_name(const std::string& name);
  /// The shm_open path of a name ("/palpate-NAME").
  static std::string path_of(const std::string& name) { return PALPATE_SHIM_PREFIX + name; }

  /// The mapped segment (null when empty).
  palpate_shim_segment* get() const noexcept { return seg_; }
  /// The link name.
  const std::string& name() const noexcept { return name_; }
  /// True once another process shrank the segment under this mapping: the access that faulted (SIGBUS) and every
  /// later one see zero-filled private pages instead, so the peer looks silent. Thread: any (an atomic load).
  bool lost() const noexcept;

 private:
  palpate_shim_segment* seg_ = nullptr;
  std::string name_;
  int guard_ = -1;  // slot of this mapping in the SIGBUS guard (-1 = none)
};

}  // namespace palpate
