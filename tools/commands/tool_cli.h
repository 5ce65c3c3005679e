#pragma once
/// The small `palpate` subcommands: video (an MP4 from a recording's frames), info (mesh counts) and scene (write a
/// scene for any mesh).

#include <CLI/CLI.hpp>

#include "tools/commands/subcommand.h"

namespace palpate {

/// Registers `video` and its options on `app`.
Subcommand add_video_command(CLI::App& app);
/// Registers `info` and its options on `app`.
Subcommand add_info_command(CLI::App& app);
/// Registers `scene` and its options on `app`.
Subcommand add_scene_command(CLI::App& app);

}  // namespace palpate
