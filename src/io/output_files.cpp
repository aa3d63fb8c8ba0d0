#include "extwrench/io/output_files.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "extwrench/core/error.hpp"

namespace extwrench {

namespace fs = std::filesystem;

OutputFiles::~OutputFiles() {
  if (kept_) return;
  std::error_code ec;
  for (const fs::path& p : staged_) fs::remove(partial_name(p), ec);
  for (const fs::path& p : committed_) fs::remove(p, ec);
  // Deepest first; a directory holding files that are not ours stays.
  for (auto d = directories_.rbegin(); d != directories_.rend(); ++d) fs::remove(*d, ec);
}

void OutputFiles::create_directories(const fs::path& dir) {
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string() + ": cannot create the directory: " + ec.message());
  directories_.insert(directories_.end(), missing.rbegin(), missing.rend());
}

fs::path OutputFiles::partial_name(const fs::path& path) {
  fs::path p = path;
  p += ".partial";
  return p;
}

void OutputFiles::check_file_target(const fs::path& path) {
  const std::string name = path.string();
  if (path.empty()) throw Error("an output file needs a name (got an empty path)");
  if (!path.has_filename()) {
    throw Error(name + ": names a directory (it ends with '/'); give a file name in it");
  }
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (ec || !fs::exists(link)) return;  // a new file (a missing directory is created or reported)
  if (fs::is_symlink(link)) {
    const fs::path target = fs::read_symlink(path, ec);
    throw Error(name + ": is a symbolic link" +
                (ec ? std::string() : " (to " + target.string() + ")") +
                ": the finished file is renamed into place, which would replace the link, not the "
                "file it points to; give that file's path");
  }
  if (fs::is_directory(link)) {
    throw Error(name + ": is a directory; give a file name in it");
  }
  if (!fs::is_regular_file(link)) {
    throw Error(name +
                ": exists and is not a regular file (a device, FIFO or socket): the "
                "finished file is renamed into place, which would replace it; give another "
                "path");
  }
}

std::string OutputFiles::cannot_create(const fs::path& path, int reason) {
  return path.string() + ": cannot create the file" +
         (reason != 0 ? std::string(": ") + std::strerror(reason) : std::string());
}

void OutputFiles::write_text(const fs::path& path, std::string_view text) {
  const fs::path partial = stage(path);
  {
    errno = 0;
    std::ofstream out(partial);
    if (!out) throw Error(cannot_create(partial, errno));  // errno: open(2)'s, when it failed
    out << text;
    out.flush();
    if (!out) throw Error(partial.string() + ": write failed (disk full?)");
  }
  commit(path);
}

fs::path OutputFiles::stage(const fs::path& path) {
  check_file_target(path);
  staged_.push_back(path);
  return partial_name(path);
}

void OutputFiles::commit(const fs::path& path) {
  const auto it = std::find(staged_.begin(), staged_.end(), path);
  if (it == staged_.end()) throw Error(path.string() + ": committed but never staged");
  std::error_code ec;
  fs::rename(partial_name(path), path, ec);
  if (ec) throw Error(path.string() + ": cannot rename the finished file: " + ec.message());
  staged_.erase(it);
  committed_.push_back(path);
}

void OutputFiles::discard(const fs::path& path) {
  const auto it = std::find(staged_.begin(), staged_.end(), path);
  if (it == staged_.end()) return;
  std::error_code ec;
  fs::remove(partial_name(path), ec);
  staged_.erase(it);
}

void OutputFiles::adopt(const fs::path& path) { committed_.push_back(path); }

}  // namespace extwrench
