// The one way the tools open a file they read (robot, configuration, scenario, log, mesh):
// a regular file of bounded size. Directories, FIFOs, sockets and devices (/dev/zero) are
// refused before anything is read, so no input can block or grow without end; a command that
// reads a stream says so explicitly ('-' for stdin). Limits: docs/cli.md "Limits".
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace extwrench {

/// Size cap of the files read whole (robot descriptions, configurations, scenarios).
inline constexpr std::uintmax_t kMaxTextFileBytes = std::uintmax_t{64} << 20;  // 64 MiB
/// Size cap of a mesh file.
inline constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{1} << 30;  // 1 GiB

/// Throws extwrench::Error unless `path` names a regular file (symbolic links followed) of at
/// most `max_bytes`: "<path>: no such <what> file", "<path>: the <what> file is a directory",
/// "<path>: the <what> file is not a regular file (a FIFO)", "... larger than N bytes ...".
void check_input_file(const std::filesystem::path& path, const std::string& what,
                      std::uintmax_t max_bytes = UINTMAX_MAX);

/// The whole content of the regular file `path` (checked as check_input_file does, on the
/// opened file, so a file swapped for a FIFO cannot block); read errors name the file.
std::string read_input_file(const std::filesystem::path& path, const std::string& what,
                            std::uintmax_t max_bytes = kMaxTextFileBytes);

/// The message for a robot file given where a text file of another kind belongs (`--config
/// arm.urdf`): "this is XML (a URDF or MJCF robot file?), but <what_belongs>". The readers
/// prefix the file and line.
std::string xml_given_instead(const std::string& what_belongs);

}  // namespace extwrench
