/* palpate_shim.h — the shared-memory link between Palpate (the "sim") and a haptic device process.
 *
 * Usable from C (C11) and C++ with GCC or Clang; needs no other Palpate header. Version 1.
 *
 * Segment: POSIX shared memory named "/palpate-<NAME>" (NAME: 1..48 of [A-Za-z0-9_.-]), exactly
 * sizeof(palpate_shim_segment) bytes, mode 0600 (owner only). The device process creates it (or re-attaches to
 * one a crashed device left behind), fills header and specs, and publishes `magic` last with release order.
 * The sim opens it, checks owner, mode, size, magic and version, and refuses anything else.
 *
 * Channels (each has exactly one writer; writers never block):
 *   pose       device -> sim   seqlock record: sequence counter, device timestamp, position, orientation, buttons
 *   force      sim -> device   seqlock record: its own counter, sim timestamp, force, the pose it answers
 *   device_hb  device -> sim   heartbeat: counter bumped every device tick
 *   sim_hb     sim -> device   heartbeat: counter bumped every servo tick
 * Each side treats the other as gone when the other's heartbeat counter stops changing for its watchdog time
 * (measured on its own clock), and everything read from the peer as untrusted (check finiteness and ranges).
 *
 * Seqlock: `lock` is odd while the writer is inside a record. Writer: lock+1 (relaxed), release fence, payload
 * (relaxed atomic stores), lock+2 (release). Reader: lock (acquire), payload (relaxed atomic loads), acquire
 * fence, lock again (relaxed); the copy is good when both equal and even. Use the helpers below.
 *
 * Units: SI (m, N, N/m, Hz); times are CLOCK_MONOTONIC nanoseconds of the writing process.
 */
#ifndef PALPATE_SHIM_H
#define PALPATE_SHIM_H

#include <stdint.h>

#define PALPATE_SHIM_MAGIC UINT64_C(0x314D485354504C50) /* "PLPTSHM1" little-endian */
#define PALPATE_SHIM_VERSION 1u
#define PALPATE_SHIM_PREFIX "/palpate-"                  /* shm_open name = prefix + NAME */
#define PALPATE_SHIM_NAME_MAX 48

#ifdef __cplusplus
#define PALPATE_SHIM_STATIC_ASSERT(c, m) static_assert(c, m)
extern "C" {
#else
#define PALPATE_SHIM_STATIC_ASSERT(c, m) _Static_assert(c, m)
#endif

/* device_state values */
enum { PALPATE_SHIM_DEVICE_STARTING = 0, PALPATE_SHIM_DEVICE_RUNNING = 1, PALPATE_SHIM_DEVICE_STOPPED = 2 };

/* 64 bytes: identification, written before `magic` is published */
typedef struct palpate_shim_header {
  uint64_t magic;         /* PALPATE_SHIM_MAGIC once the segment is ready */
  uint32_t version;       /* PALPATE_SHIM_VERSION */
  uint32_t segment_size;  /* sizeof(palpate_shim_segment) */
  uint64_t device_pid;    /* pid of the serving device process */
  uint64_t device_epoch;  /* +1 each time a device process attaches (restart detection) */
  uint64_t device_state;  /* PALPATE_SHIM_DEVICE_* (atomic) */
  uint64_t reserved[3];
} palpate_shim_header;

/* 64 bytes: what the device can do; fixed while a device process is attached */
typedef struct palpate_shim_specs {
  double max_force_N;           /* force the device can render */
  double max_stiffness_N_per_m; /* highest stable rendered stiffness */
  double workspace_half_m;      /* poses lie in the cube [-w, w]^3 */
  double rate_hz;               /* the device's own tick rate */
  double reserved[4];
} palpate_shim_specs;

/* one device reading (80 bytes) */
typedef struct palpate_shim_pose {
  uint64_t seq;           /* +1 per new reading */
  int64_t time_ns;        /* device clock at sampling */
  double pos_m[3];        /* handle position, world frame */
  double quat_wxyz[4];    /* handle orientation */
  uint64_t buttons;       /* bit 0 = main button */
} palpate_shim_pose;

/* one force command (56 bytes) */
typedef struct palpate_shim_force {
  uint64_t seq;           /* +1 per command */
  int64_t time_ns;        /* sim clock when sent */
  double force_N[3];      /* force to render until the next command */
  uint64_t pose_seq;      /* seq of the pose this force answers (0: none) */
  int64_t pose_time_ns;   /* that pose's time_ns, echoed for round-trip timing */
} palpate_shim_force;

typedef struct palpate_shim_pose_slot {
  uint64_t lock;
  palpate_shim_pose pose;
  uint64_t pad[5];
} palpate_shim_pose_slot;     /* 128 bytes */

typedef struct palpate_shim_force_slot {
  uint64_t lock;
  palpate_shim_force force;
} palpate_shim_force_slot;    /* 64 bytes */

typedef struct palpate_shim_heartbeat {
  uint64_t count;         /* bumped every tick of the writing side */
  int64_t time_ns;        /* writer's clock at the last bump */
  uint64_t pad[6];
} palpate_shim_heartbeat;     /* 64 bytes */

/* the whole segment (448 bytes); each writer's data on its own cache lines */
typedef struct palpate_shim_segment {
  palpate_shim_header header;
  palpate_shim_specs specs;
  palpate_shim_pose_slot pose;
  palpate_shim_force_slot force;
  palpate_shim_heartbeat device_hb;
  palpate_shim_heartbeat sim_hb;
} palpate_shim_segment;

PALPATE_SHIM_STATIC_ASSERT(sizeof(palpate_shim_header) == 64, "header layout");
PALPATE_SHIM_STATIC_ASSERT(sizeof(palpate_shim_specs) == 64, "specs layout");
PALPATE_SHIM_STATIC_ASSERT(sizeof(palpate_shim_pose_slot) == 128, "pose layout");
PALPATE_SHIM_STATIC_ASSERT(sizeof(palpate_shim_force_slot) == 64, "force layout");
PALPATE_SHIM_STATIC_ASSERT(sizeof(palpate_shim_heartbeat) == 64, "heartbeat layout");
PALPATE_SHIM_STATIC_ASSERT(sizeof(palpate_shim_segment) == 448, "segment layout");

/* relaxed per-field copies: no torn words, no data race in the C/C++ memory models. A translation unit may
   define PALPATE_SHIM_LD before including this header to interpose on the readers' field loads (the tests use it
   to put a whole write between two loads of one copy, deterministically). */
#if defined(__cplusplus)
/* (clang's C++ front end takes no pointer to const as __atomic_store's value: the cast drops it, nothing is
   written through it) */
#define PALPATE_SHIM_ST(dst, src) __atomic_store(&(dst), const_cast<__typeof__(dst)*>(&(src)), __ATOMIC_RELAXED)
#else
#define PALPATE_SHIM_ST(dst, src) __atomic_store(&(dst), &(src), __ATOMIC_RELAXED)
#endif
#ifndef PALPATE_SHIM_LD
#define PALPATE_SHIM_LD(src, dst) __atomic_load(&(src), &(dst), __ATOMIC_RELAXED)
#endif

/* Makes the lock even again (a writer that died inside a record leaves it odd). Writer side, at attach. */
static inline void palpate_shim_lock_repair(uint64_t* lock) {
  const uint64_t l = __atomic_load_n(lock, __ATOMIC_RELAXED);
  if (l & 1u) __atomic_store_n(lock, l + 1u, __ATOMIC_RELEASE);
}

/* Publishes a pose. Device side only; never blocks. */
static inline void palpate_shim_write_pose(palpate_shim_pose_slot* s, const palpate_shim_pose* p) {
  /* the only writer finds the lock even; an odd one was left by a write that never finished (or a stray
     write): start from the next even value, or every later record would read as torn */
  const uint64_t l = (__atomic_load_n(&s->lock, __ATOMIC_RELAXED) + 1u) & ~UINT64_C(1);
  __atomic_store_n(&s->lock, l + 1u, __ATOMIC_RELAXED);
  __atomic_thread_fence(__ATOMIC_RELEASE);
  PALPATE_SHIM_ST(s->pose.seq, p->seq);
  PALPATE_SHIM_ST(s->pose.time_ns, p->time_ns);
  for (int i = 0; i < 3; ++i) PALPATE_SHIM_ST(s->pose.pos_m[i], p->pos_m[i]);
  for (int i = 0; i < 4; ++i) PALPATE_SHIM_ST(s->pose.quat_wxyz[i], p->quat_wxyz[i]);
  PALPATE_SHIM_ST(s->pose.buttons, p->buttons);
  __atomic_store_n(&s->lock, l + 2u, __ATOMIC_RELEASE);
}

/* Copies the latest pose; returns 1 on a consistent copy, 0 when the writer was busy `tries` times. Sim side. */
static inline int palpate_shim_read_pose(const palpate_shim_pose_slot* s, palpate_shim_pose* p, int tries) {
  for (int k = 0; k < tries; ++k) {
    const uint64_t l0 = __atomic_load_n(&s->lock, __ATOMIC_ACQUIRE);
    if (l0 & 1u) continue;
    PALPATE_SHIM_LD(s->pose.seq, p->seq);
    PALPATE_SHIM_LD(s->pose.time_ns, p->time_ns);
    for (int i = 0; i < 3; ++i) PALPATE_SHIM_LD(s->pose.pos_m[i], p->pos_m[i]);
    for (int i = 0; i < 4; ++i) PALPATE_SHIM_LD(s->pose.quat_wxyz[i], p->quat_wxyz[i]);
    PALPATE_SHIM_LD(s->pose.buttons, p->buttons);
    __atomic_thread_fence(__ATOMIC_ACQUIRE);
    if (__atomic_load_n(&s->lock, __ATOMIC_RELAXED) == l0) return 1;
  }
  return 0;
}

/* Publishes a force command. Sim side only; never blocks. */
static inline void palpate_shim_write_force(palpate_shim_force_slot* s, const palpate_shim_force* f) {
  /* as for the pose: an odd lock left by an unfinished write is mended, not carried on */
  const uint64_t l = (__atomic_load_n(&s->lock, __ATOMIC_RELAXED) + 1u) & ~UINT64_C(1);
  __atomic_store_n(&s->lock, l + 1u, __ATOMIC_RELAXED);
  __atomic_thread_fence(__ATOMIC_RELEASE);
  PALPATE_SHIM_ST(s->force.seq, f->seq);
  PALPATE_SHIM_ST(s->force.time_ns, f->time_ns);
  for (int i = 0; i < 3; ++i) PALPATE_SHIM_ST(s->force.force_N[i], f->force_N[i]);
  PALPATE_SHIM_ST(s->force.pose_seq, f->pose_seq);
  PALPATE_SHIM_ST(s->force.pose_time_ns, f->pose_time_ns);
  __atomic_store_n(&s->lock, l + 2u, __ATOMIC_RELEASE);
}

/* Copies the latest force command; 1 on a consistent copy, 0 when the writer was busy `tries` times. Device side. */
static inline int palpate_shim_read_force(const palpate_shim_force_slot* s, palpate_shim_force* f, int tries) {
  for (int k = 0; k < tries; ++k) {
    const uint64_t l0 = __atomic_load_n(&s->lock, __ATOMIC_ACQUIRE);
    if (l0 & 1u) continue;
    PALPATE_SHIM_LD(s->force.seq, f->seq);
    PALPATE_SHIM_LD(s->force.time_ns, f->time_ns);
    for (int i = 0; i < 3; ++i) PALPATE_SHIM_LD(s->force.force_N[i], f->force_N[i]);
    PALPATE_SHIM_LD(s->force.pose_seq, f->pose_seq);
    PALPATE_SHIM_LD(s->force.pose_time_ns, f->pose_time_ns);
    __atomic_thread_fence(__ATOMIC_ACQUIRE);
    if (__atomic_load_n(&s->lock, __ATOMIC_RELAXED) == l0) return 1;
  }
  return 0;
}

/* Bumps a heartbeat (its one writer only). */
static inline void palpate_shim_beat(palpate_shim_heartbeat* hb, int64_t now_ns) {
  __atomic_store_n(&hb->time_ns, now_ns, __ATOMIC_RELAXED);
  __atomic_store_n(&hb->count, __atomic_load_n(&hb->count, __ATOMIC_RELAXED) + 1u, __ATOMIC_RELEASE);
}

/* The heartbeat counter as last written by the peer. */
static inline uint64_t palpate_shim_beats(const palpate_shim_heartbeat* hb) {
  return __atomic_load_n(&hb->count, __ATOMIC_ACQUIRE);
}

#ifdef __cplusplus
}
#endif

#endif /* PALPATE_SHIM_H */
