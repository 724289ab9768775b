#include "crowdrecon/common/output_path.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>
#include <vector>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <utility>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/remove_on_interrupt.hpp"

namespace crowdrecon {

namespace fs = std::filesystem;

namespace {

// The first `n` bytes of a file ("" if unreadable).
std::string Head(const fs::path& file, std::size_t n) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes(n, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(n));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(0, in.gcount())));
  return bytes;
}

// A name for messages, cut to a sensible length.
std::string Shortened(const std::string& text, std::size_t max = 60) {
  return text.size() <= max ? text : text.substr(0, max - 3) + "...";
}

bool IsSvg(const std::string& head) {
  const auto first = head.find_first_not_of(" \t\r\n");
  return first != std::string::npos && head[first] == '<' && head.find("<svg") != std::string::npos;
}

std::string DescribeFile(const fs::path& file) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (!ec && size == 0) return "an empty file";
  const std::string head = Head(file, 1024);
  if (head.rfind(std::string("SQLite format 3\0", 16), 0) == 0) return "a SQLite file";
  if (head.rfind("\x89PNG", 0) == 0) return "a PNG picture";
  if (head.rfind("%PDF", 0) == 0) return "a PDF file";
  if (head.rfind("RIFF", 0) == 0 && head.compare(8, 4, "AVI ") == 0) return "an AVI video";
  if (head.size() >= 8 && head.compare(4, 4, "ftyp") == 0) return "an MP4 video";
  if (IsSvg(head)) return "an SVG picture";
  const auto first = head.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && (head[first] == '{' || head[first] == '[')) return "a JSON file";
  if (first != std::string::npos && head[first] == '<') return "an XML or HTML file";
  const bool text = std::all_of(head.begin(), head.end(), [](unsigned char c) { return c >= 0x20 || c == '\n' || c == '\r' || c == '\t'; });
  return std::string(text ? "a text file" : "a binary file") + " of " + std::to_string(ec ? 0 : size) + " bytes";
}

std::string DescribeFolder(const fs::path& folder) {
  std::error_code ec;
  std::vector<std::string> names;
  std::size_t count = 0;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (names.size() < 3) names.push_back(Shortened(it->path().filename().string(), 40));
    ++count;
  }
  if (count == 0) return "an empty folder";
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  if (count > names.size()) list += ", ...";
  return "a folder holding " + std::to_string(count) + (count == 1 ? " entry (" : " entries (") + list + ")";
}

// Same file or folder: through links where both exist, else by their
// absolute, normalised paths (outputs not yet written).
bool SamePath(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    return !ec && same;
  }
  std::error_code ea, eb;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ea), ea), cb = fs::weakly_canonical(fs::absolute(b, eb), eb);
  return !ea && !eb && ca == cb;
}

void CheckOne(const PlannedOutput& out, const std::vector<NamedInput>& inputs, bool force) {
  const std::string where = out.option + " " + Shortened(out.path.string(), 200);
  for (const NamedInput& in : inputs)
    if (!in.path.empty() && SamePath(out.path, in.path))
      throw InputError(where + ": is " + in.what + " (" + Shortened(in.path.string(), 200) +
                       "), an input of this command; an input is never overwritten, not even with --force; "
                       "choose another name");
  // A file's name that ends with a separator (or is . or ..) names a folder:
  // the file would be written beside it under another name (issue 65:
  // simulate -o x/ wrote a run file "x" and failed at its first checkpoint).
  const std::string name = out.path.filename().string();
  if (!out.kind.folder && (name.empty() || name == "." || name == ".."))
    throw InputError(where + ": names a folder, not " + out.kind.name + "; give a file name (such as " +
                     Shortened((out.path / "out").string(), 200) + " with its extension)");
  std::error_code ec;
  // A file goes into a folder that exists (issue 65: `timeline --scores
  // missing/s.csv` failed only after its figure was written).
  if (!out.kind.folder) {
    const fs::path parent = out.path.parent_path().empty() ? fs::path(".") : out.path.parent_path();
    if (!fs::exists(parent, ec))
      throw InputError(where + ": its folder " + Shortened(parent.string(), 200) +
                       " does not exist; expected an existing folder (no folder is made for a file)");
    if (!fs::is_directory(parent, ec))
      throw InputError(where + ": " + Shortened(parent.string(), 200) + " is " + DescribeExisting(parent) +
                       ", not a folder; expected an existing folder");
  }
  const fs::file_status link = fs::symlink_status(out.path, ec);
  if (!fs::exists(link)) return;  // nothing there: nothing to lose
  const std::string there = out.kind.describe ? out.kind.describe(out.path) : DescribeExisting(out.path);
  const bool folder = fs::is_directory(out.path, ec);
  const bool empty_folder = folder && fs::is_empty(out.path, ec);
  if (!out.kind.folder && folder)
    throw InputError(where + ": exists and is " + there + ", not " + out.kind.name +
                     "; a folder is never replaced by a file, not even with --force; give a file name");
  if (out.kind.folder && !folder)
    throw InputError(where + ": exists and is " + there + ", not a folder for " + out.kind.name +
                     "; choose another name");
  if (!folder && !fs::is_regular_file(out.path, ec))
    throw InputError(where + ": exists and is " + there + ", not " + out.kind.name + "; choose another name");
  // An empty file or folder holds nothing to lose (a run killed as it began leaves one).
  const bool empty_file = !folder && fs::file_size(out.path, ec) == 0 && !ec;
  if (empty_folder || empty_file || (out.kind.is_previous && out.kind.is_previous(out.path)) || force) return;
  throw InputError(where + ": exists and is " + there + ", not " + out.kind.name + "; choose another name or --force" +
                   (folder ? " (which writes into the folder and deletes nothing in it)" : " (which replaces it)"));
}

}  // namespace

void CheckOutputs(const std::vector<PlannedOutput>& outputs, const std::vector<NamedInput>& inputs, bool force) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].path.empty()) continue;
    for (std::size_t j = 0; j < i; ++j)
      if (!outputs[j].path.empty() && SamePath(outputs[i].path, outputs[j].path))
        throw InputError(outputs[j].option + " and " + outputs[i].option + " both name " +
                         Shortened(outputs[i].path.string(), 200) + "; give each output its own name");
    CheckOne(outputs[i], inputs, force);
  }
}

std::string DescribeExisting(const fs::path& path) {
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (!fs::exists(link)) return "nothing";
  const fs::file_status target = fs::status(path, ec);
  if (!fs::exists(target)) return "a broken symbolic link";
  if (fs::is_directory(target)) return DescribeFolder(path);
  if (fs::is_regular_file(target)) return DescribeFile(path);
  return "a special file (a device, pipe or socket)";
}

fs::path PartialPath(const fs::path& file) {
  return file.parent_path() /
         ("." + file.stem().string() + ".partial-" + std::to_string(::getpid()) + file.extension().string());
}

void WriteWholeFile(const fs::path& path, const std::string& text, const fs::path& named) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(named.string() + ": cannot open a file for writing next to it (" + path.string() + ")");
  out << text;
  out.flush();
  if (!out) throw InputError(named.string() + ": error while writing (disk full?)");
}

std::vector<fs::path> WriteFileAtomically(const fs::path& file, const std::string& text) {
  return WriteFilesAtomically({{file, text}});
}

std::vector<fs::path> WriteFilesAtomically(const std::vector<std::pair<fs::path, std::string>>& files) {
  std::vector<fs::path> partials, stale;
  for (const auto& file : files)
    for (const fs::path& p : RemoveStalePartialsOf(file.first)) stale.push_back(p);
  std::vector<std::unique_ptr<RemoveOnInterrupt>> remove_on_interrupt;
  const auto remove_partials = [&partials](std::size_t from) {
    std::error_code ignored;
    for (std::size_t k = from; k < partials.size(); ++k) fs::remove(partials[k], ignored);
  };
  // Every file complete under its partial name first...
  for (const auto& [file, text] : files) {
    partials.push_back(PartialPath(file));
    remove_on_interrupt.push_back(std::make_unique<RemoveOnInterrupt>(partials.back()));
    try {
      WriteWholeFile(partials.back(), text, file);
    } catch (const InputError&) {
      remove_partials(0);
      throw;
    }
  }
  // ... then each renamed in place.
  for (std::size_t k = 0; k < files.size(); ++k) {
    std::error_code ec;
    fs::rename(partials[k], files[k].first, ec);
    if (ec) {
      remove_partials(k);
      throw InputError(files[k].first.string() + ": cannot write: " + ec.message());
    }
  }
  return stale;
}

bool FileStartsWith(const fs::path& file, const std::string& magic, std::size_t offset) {
  const std::string head = Head(file, offset + magic.size());
  return head.size() == offset + magic.size() && head.compare(offset, magic.size(), magic) == 0;
}

bool IsStalePartial(const fs::path& file) {
  const std::string name = file.filename().string();
  const auto at = name.find(".partial-");
  if (name.empty() || name[0] != '.' || at == std::string::npos) return false;
  const std::string rest = name.substr(at + 9);
  const std::string digits = rest.substr(0, rest.find('.'));
  if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return false;
  const pid_t pid = static_cast<pid_t>(std::stol(digits));
  return pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH;
}

namespace {

// Removes the entries of `folder` (not recursive, in name order) that
// `remove` picks; returns those removed.
std::vector<fs::path> RemoveEntries(const fs::path& folder, const std::function<bool(const fs::path&)>& remove) {
  std::vector<fs::path> entries, removed;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) entries.push_back(it->path());
  std::sort(entries.begin(), entries.end());
  for (const fs::path& p : entries) {
    if (!remove(p)) continue;
    std::error_code gone;
    fs::remove_all(p, gone);
    if (!gone) removed.push_back(p);
  }
  return removed;
}

}  // namespace

std::vector<fs::path> RemoveLeftovers(const fs::path& folder, const std::vector<std::string>& leftovers) {
  return RemoveEntries(folder, [&](const fs::path& p) {
    return IsStalePartial(p) || std::find(leftovers.begin(), leftovers.end(), p.filename().string()) != leftovers.end();
  });
}

std::vector<fs::path> RemoveStalePartialsOf(const fs::path& file) {
  const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  const std::string prefix = "." + file.stem().string() + ".partial-", extension = file.extension().string();
  return RemoveEntries(folder, [&](const fs::path& p) {
    // ".NAME.partial-PID" + the extension, exactly (a name without one, as
    // a folder's, has ".partial-PID" for its extension).
    const std::string name = p.filename().string();
    if (name.rfind(prefix, 0) != 0 || name.size() < prefix.size() + extension.size() ||
        name.compare(name.size() - extension.size(), extension.size(), extension) != 0)
      return false;
    const std::string pid = name.substr(prefix.size(), name.size() - prefix.size() - extension.size());
    return !pid.empty() && pid.find_first_not_of("0123456789") == std::string::npos && IsStalePartial(p);
  });
}

bool FolderHoldsOnly(const fs::path& folder, const std::function<bool(const fs::directory_entry&)>& ours) {
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
    if (!ours(*it)) return false;
  return !ec;
}

OutputKind JsonOutputKind(std::string name, std::function<bool(const nlohmann::json&)> matches) {
  return {std::move(name), false, [matches = std::move(matches)](const fs::path& file) {
            const std::string head = Head(file, 64);
            const auto first = head.find_first_not_of(" \t\r\n");
            if (first == std::string::npos || head[first] != '{') return false;
            std::ifstream in(file, std::ios::binary);
            const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
            const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
            return j.is_object() && matches(j);
          }};
}

OutputKind PictureOutputKind() {
  return {"a picture (PNG, SVG or PDF)", false, [](const fs::path& file) {
            return FileStartsWith(file, "\x89PNG") || FileStartsWith(file, "%PDF") || IsSvg(Head(file, 1024));
          }};
}

OutputKind VideoOutputKind() {
  return {"a video (MP4 or AVI)", false, [](const fs::path& file) {
            return FileStartsWith(file, "ftyp", 4) || (FileStartsWith(file, "RIFF") && FileStartsWith(file, "AVI ", 8));
          }};
}

void RefuseRepeatedFiles(const std::vector<std::filesystem::path>& files, const std::string& why) {
  for (std::size_t k = 0; k < files.size(); ++k)
    for (std::size_t j = 0; j < k; ++j) {
      std::error_code ec;
      if (std::filesystem::equivalent(files[j], files[k], ec))
        throw InputError(files[k].string() + ": given twice (also as " + files[j].string() + "); " + why);
    }
}

void CreateOutputFolder(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!ec && std::filesystem::is_directory(dir, ec)) return;
  std::string why = ec ? ec.message() : "";
  std::error_code ignored;
  if (std::filesystem::exists(dir, ignored) && !std::filesystem::is_directory(dir, ignored))
    why = "it exists and is " + DescribeExisting(dir) + ", not a folder";
  throw InputError(dir.string() + ": cannot create the output folder" + (why.empty() ? "" : ": " + why) +
                   "; expected a folder that can be made (a writable parent, names of at most 255 bytes)");
}

}  // namespace crowdrecon
