#pragma once
// --vtu-compression: how the .vtu files of a command are compressed
// (toolkit::io::VtuCompression), the same words and help for every command.
#include <CLI/CLI.hpp>
#include <string>

#include "toolkit/io/vtu_writer.h"

namespace tspline_app {

inline constexpr const char* kVtuCompressionHelp =
    "Compression of the .vtu files: 'lz4' (fast to write and to read), 'zlib' (files about a quarter "
    "smaller, several times the CPU to write) or 'none'; ParaView and VTK read all three";

/// Adds --vtu-compression lz4|zlib|none (default lz4) to `cmd`, setting `target`.
inline void add_vtu_compression_option(CLI::App* cmd, toolkit::io::VtuCompression& target) {
  cmd->add_option_function<std::string>(
         "--vtu-compression",
         [&target](const std::string& v) { target = toolkit::io::parse_vtu_compression(v); },
         kVtuCompressionHelp)
      ->check(CLI::IsMember({"lz4", "zlib", "none"}))
      ->default_str("lz4");
}

}  // namespace tspline_app
