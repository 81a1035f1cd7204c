#pragma once
// Writing files so that a reader never sees half a file: write to a temporary
// name in the same directory, then rename over the target.
#include <functional>
#include <string>

namespace toolkit::io {

/// Writes `content` to `path` atomically. \throw IoError naming the path and the reason.
void write_text_atomic(const std::string& path, const std::string& content);

/// Calls `write(tmp_path)` to produce the file under a temporary name in the
/// target's directory, then renames it to `path`. The temporary is removed if
/// `write` throws or the rename fails. \throw IoError.
void write_atomic(const std::string& path, const std::function<void(const std::string& tmp_path)>& write);

/// Creates `dir` (and parents) if missing and checks that it is writable.
/// \throw IoError naming the directory if it cannot be created or written.
void ensure_writable_directory(const std::string& dir);

/// Checks, without creating anything, that `dir` could be created and written:
/// it is a writable directory, or its nearest existing ancestor is one (for
/// programs that create their output folder only once there is something to
/// put in it). \throw IoError naming the directory and the reason.
void check_writable_directory(const std::string& dir);

}  // namespace toolkit::io
