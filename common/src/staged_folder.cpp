#include "crowdrecon/common/staged_folder.hpp"

#include <fcntl.h>     // AT_FDCWD
#include <stdio.h>     // renameat2, RENAME_EXCHANGE (glibc 2.28+)
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/remove_on_interrupt.hpp"

namespace crowdrecon {

namespace fs = std::filesystem;

namespace {

// The folder named without a trailing separator ("out/report/" names
// "out/report"); through a symbolic link, the folder it points to (the link
// stays a link).
fs::path FolderItself(const fs::path& folder) {
  fs::path f = folder.lexically_normal();
  if (f.filename().empty()) f = f.parent_path();
  std::error_code ec;
  if (fs::is_symlink(f, ec) && fs::is_directory(f, ec)) f = fs::canonical(f, ec);
  return f;
}

constexpr std::size_t kNameMax = 255;  // bytes of a file name (Linux's NAME_MAX)
// The staging folder of an output whose name leaves no room for the
// partial's additions (under PartialPath's name of this).
constexpr const char* kLongNameStaging = "crowdrecon-output";

// Where the fallback of Commit moves the previous output aside (under
// PartialPath's name of this).
fs::path Aside(const fs::path& folder) { return folder.parent_path() / (folder.filename().string() + "-previous"); }

bool IsEmptyFolder(const fs::path& folder) {
  std::error_code ec;
  return fs::is_directory(folder, ec) && fs::is_empty(folder, ec) && !ec;
}

}  // namespace

StagedFolder::StagedFolder(const fs::path& folder, const OutputKind& kind)
    : folder_(FolderItself(folder)), kind_(kind) {
  const auto cannot = [&folder](const std::string& why) {
    return InputError(folder.string() + ": cannot create the output folder: " + why +
                      "; expected a folder that can be made (a writable parent, names of at most 255 bytes)");
  };
  if (folder_.filename().string().size() > kNameMax) throw cannot("File name too long");
  const fs::path parent = folder_.parent_path().empty() ? fs::path(".") : folder_.parent_path();
  CreateOutputFolder(parent);
  removed_ = RemoveStalePartialsOf(folder_);
  for (const fs::path& p : RemoveStalePartialsOf(Aside(folder_))) removed_.push_back(p);
  for (const fs::path& p : RemoveStalePartialsOf(parent / kLongNameStaging)) removed_.push_back(p);
  staging_ = PartialPath(folder_);
  // A name near the limit has no room for the partial's additions.
  if (staging_.filename().string().size() > kNameMax) staging_ = PartialPath(parent / kLongNameStaging);
  std::error_code ec;
  fs::remove_all(staging_, ec);  // this process's own, from an earlier output of the same name
  if (!fs::create_directory(staging_, ec) || ec) throw cannot(ec ? ec.message() : "it exists");
  remove_on_interrupt_.push_back(std::make_unique<RemoveOnInterrupt>(staging_));
}

StagedFolder::~StagedFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void StagedFolder::Write(const std::string& name, const std::string& text) {
  const fs::path file = staging_ / name;
  remove_on_interrupt_.push_back(std::make_unique<RemoveOnInterrupt>(file));
  WriteWholeFile(file, text, folder_ / name);  // (what it leaves goes with the staging folder)
}

void StagedFolder::Commit() {
  std::error_code ec;
  const bool exists = fs::exists(fs::symlink_status(folder_, ec));
  if (!exists) {
    fs::rename(staging_, folder_, ec);
    if (ec) throw InputError(folder_.string() + ": cannot put the output in place: " + ec.message());
  } else if (IsEmptyFolder(folder_) || (fs::is_directory(folder_, ec) && kind_.is_previous(folder_))) {
    // The previous output swapped for the new one in one step; the previous
    // one, now under the staging name, removed after.
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, folder_.c_str(), RENAME_EXCHANGE) != 0) {
      const int error = errno;
      if (error != EINVAL && error != ENOSYS)
        throw InputError(folder_.string() + ": cannot put the output in place: " + std::strerror(error));
      // A file system without the exchange: two renames, the old folder
      // first moved aside under a partial name (removed by the next run if
      // a kill came between them).
      const fs::path aside = PartialPath(Aside(folder_));
      fs::rename(folder_, aside, ec);
      if (!ec) fs::rename(staging_, folder_, ec);
      if (ec) throw InputError(folder_.string() + ": cannot put the output in place: " + ec.message());
      fs::remove_all(aside, ec);
    } else {
      fs::remove_all(staging_, ec);
    }
  } else {
    // A foreign folder (--force): the staged files moved in one by one.
    for (fs::directory_iterator it(staging_, ec), end; !ec && it != end; it.increment(ec)) {
      std::error_code moved;
      fs::rename(it->path(), folder_ / it->path().filename(), moved);
      if (moved)
        throw InputError((folder_ / it->path().filename()).string() + ": cannot put the output in place: " +
                         moved.message());
    }
    fs::remove_all(staging_, ec);
  }
  committed_ = true;
}

}  // namespace crowdrecon
