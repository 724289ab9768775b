// A folder output replaced as a whole (a report: report.html, report.pdf and
// people.csv). Its files are written into a hidden staging folder beside it
// (PartialPath's name, ".NAME.partial-PID"); Commit() then puts the staging
// folder in place of the output folder in one rename (Linux's
// renameat2 RENAME_EXCHANGE where the output folder exists) and removes what
// the folder held before. Until Commit, the output folder is untouched: an
// error, Ctrl-C or a kill leaves the previous output as it was, never new
// files beside old ones made with other options.
//
// Only a previous output of the folder's kind (or an empty folder) is
// replaced as a whole. A foreign folder (written into with --force, whose
// other entries are left alone) receives the staged files one by one, each
// complete, after all are written.
//
// A staging folder a killed writer left (its PID no longer runs) is removed
// by the next StagedFolder of the same output, which says so (removed()).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"

namespace crowdrecon {

class RemoveOnInterrupt;

class StagedFolder {
 public:
  // Creates the staging folder beside `folder` (and `folder`'s parents);
  // throws InputError if it cannot be made.
  StagedFolder(const std::filesystem::path& folder, const OutputKind& kind);
  ~StagedFolder();  // without Commit: the staging folder and its files removed
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  // Where to write the output's files until Commit.
  const std::filesystem::path& path() const { return staging_; }
  // Writes `name` into the staging folder (removed on Ctrl-C with it);
  // throws InputError on a write error (disk full).
  void Write(const std::string& name, const std::string& text);
  // Puts the staged files in place (see above); the staging folder is gone.
  void Commit();
  // Stale staging folders of earlier, killed writers that the constructor removed.
  const std::vector<std::filesystem::path>& removed() const { return removed_; }

 private:
  std::filesystem::path folder_, staging_;
  OutputKind kind_;
  std::vector<std::filesystem::path> removed_;
  std::vector<std::unique_ptr<RemoveOnInterrupt>> remove_on_interrupt_;
  bool committed_ = false;
};

}  // namespace crowdrecon
