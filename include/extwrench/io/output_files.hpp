// The files a command writes, as one transaction: each file is written to "<name>.partial" in
// its final directory and renamed to its name when complete; when the command fails (the
// object is destroyed without keep()), every file and directory it created is removed again,
// so a failed command leaves nothing that looks like a result (docs/cli.md "Outputs").
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace extwrench {

class OutputFiles {
 public:
  OutputFiles() = default;
  /// Rolls back unless keep() was called: removes staged and committed files, then the
  /// directories create_directories() made (when empty). Never throws.
  ~OutputFiles();
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;

  /// Creates `dir` and its missing parents, remembering the ones it made.
  void create_directories(const std::filesystem::path& dir);
  /// The name to write `path` under until commit(path): "<path>.partial".
  std::filesystem::path stage(const std::filesystem::path& path);
  /// The staged file of `path` is complete: renames it to `path` (atomic, same directory).
  void commit(const std::filesystem::path& path);
  /// The staged file of `path` is not wanted (a figure that failed): removes "<path>.partial"
  /// now; the rest of the transaction is unaffected.
  void discard(const std::filesystem::path& path);
  /// stage(path), the text written, flushed and checked, commit(path): a small text file in one
  /// call. Throws extwrench::Error naming the file when it cannot be created or written.
  void write_text(const std::filesystem::path& path, std::string_view text);
  /// Registers a file written directly under its name (figures), to remove on rollback.
  void adopt(const std::filesystem::path& path);
  /// The files committed or adopted so far (to hand a nested transaction's files to its parent).
  [[nodiscard]] const std::vector<std::filesystem::path>& committed() const { return committed_; }
  /// The command succeeded: keep every file.
  void keep() { kept_ = true; }

  /// "<path>.partial".
  static std::filesystem::path partial_name(const std::filesystem::path& path);
  /// Throws extwrench::Error unless `path` can be written by stage() and commit(): it must not
  /// name a directory (or end with '/'), a symbolic link (the rename would replace the link, not
  /// the file it points to) or an existing file that is not regular (a device, a FIFO: the
  /// rename would replace /dev/full by a plain file). stage() checks it; commands call it before
  /// their work, so that a bad --out fails at once.
  static void check_file_target(const std::filesystem::path& path);
  /// "PATH: cannot create the file[: REASON]", REASON from errno when open(2) set it.
  static std::string cannot_create(const std::filesystem::path& path, int reason);

 private:
  std::vector<std::filesystem::path> staged_;
  std::vector<std::filesystem::path> committed_;
  std::vector<std::filesystem::path> directories_;
  bool kept_ = false;
};

}  // namespace extwrench
