/* palpate_plugin.h — the C ABI of a Palpate device plugin (a shared object loaded with `--device plugin:PATH`).
 *
 * A plugin wraps a device SDK (OpenHaptics, Force Dimension, libnifalcon, ...) and is built apart from Palpate:
 * it needs only this header. It exports one symbol, `palpate_plugin_entry`, returning a static table.
 *
 * Threads: open/specs/close are called from Palpate's main thread; read_pose and write_force from its 1 kHz
 * servo thread, once each per tick, and must not block (no locks held for long, no I/O waits, no allocation).
 * Units: SI (m, N, N/m, Hz), world frame. Palpate checks everything a plugin returns (finite, in workspace).
 */
#ifndef PALPATE_PLUGIN_H
#define PALPATE_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#define PALPATE_PLUGIN_ABI_VERSION 1u
#define PALPATE_PLUGIN_ENTRY "palpate_plugin_entry"

#ifdef __cplusplus
extern "C" {
#endif

/* what the device can do */
typedef struct palpate_plugin_specs {
  double max_force_N;
  double max_stiffness_N_per_m;
  double workspace_half_m;  /* poses lie in [-w, w]^3 */
  double rate_hz;
} palpate_plugin_specs;

/* one reading */
typedef struct palpate_plugin_pose {
  double pos_m[3];
  double quat_wxyz[4];
  uint64_t buttons;         /* bit 0 = main button */
} palpate_plugin_pose;

typedef struct palpate_plugin_api {
  uint32_t abi_version;     /* PALPATE_PLUGIN_ABI_VERSION */
  uint32_t struct_size;     /* sizeof(palpate_plugin_api) */
  const char* name;         /* shown in logs */
  /* Opens the device. `config` holds `key=value` pairs separated by ';' (keys a plugin does not know are to be
   * ignored); Palpate passes scene=<path>, hand=<mass_kg>,<stiffness_N_per_m>,<damping_Ns_per_m> and one
   * key=<t_s>,<x_m>,<y_m>,<z_m>,<button> per trajectory keyframe (numbers as C99 hex floats). Returns NULL on
   * failure with a one-line message in `error`. */
  void* (*open)(const char* config, char* error, size_t error_size);
  /* Fills the device's limits; returns 1, or 0 on failure. */
  int (*specs)(void* dev, palpate_plugin_specs* out);
  /* Reads the pose at scene time t_s; returns 1 with a reading, 0 when none is available. */
  int (*read_pose)(void* dev, double t_s, palpate_plugin_pose* out);
  /* Commands a force (N), applied until the next call. */
  void (*write_force)(void* dev, const double force_N[3]);
  /* Releases the device (force off). */
  void (*close)(void* dev);
} palpate_plugin_api;

/* The one exported function: returns the plugin's table (static storage). */
typedef const palpate_plugin_api* (*palpate_plugin_entry_fn)(void);

#ifdef __cplusplus
}
#endif

#endif /* PALPATE_PLUGIN_H */
