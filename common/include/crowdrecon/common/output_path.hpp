// Outputs never destroy anything. Every command that writes checks its output
// paths with CheckOutputs before it computes anything, and writes whole files
// with WriteFileAtomically:
//
//   - an input is never an output (compared with std::filesystem::equivalent,
//     so also through symlinks and hard links), not even with --force;
//   - a folder is never replaced by a file, and nothing in a folder is deleted;
//   - an existing path that is a previous output of the same kind (a run file,
//     a body JSON, a frames folder, ...) is replaced or written into: that is
//     how a command is run again; so is an empty file or an empty folder of
//     the right type, which holds nothing to lose;
//   - anything else that exists is refused with a message saying what is
//     there, unless --force is given (a file is then replaced; a folder is
//     written into, and what it holds is left alone);
//   - two outputs of one command never name the same path.
//
// A module that owns a file format describes its previous outputs with an
// OutputKind (runfile::RunFileOutput(), geometry::BodyJsonOutput(), ...), so
// a new command gets the rule by listing its outputs and inputs.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace crowdrecon {

// How to recognise a previous output of one kind.
struct OutputKind {
  std::string name;     // for messages: "crowdrecon run file", "frames folder"
  bool folder = false;  // a folder of files rather than one file
  // Called on an existing path (a regular file, or for folder kinds a
  // non-empty folder): true if it is a previous output of this kind.
  std::function<bool(const std::filesystem::path&)> is_previous;
  // Optional: what an existing path that is no previous output is, where the
  // kind can say more than DescribeExisting ("a damaged SQLite file (...)").
  std::function<std::string(const std::filesystem::path&)> describe = {};
};

struct PlannedOutput {
  std::string option;          // how the user named it: "-o", "--picture"
  std::filesystem::path path;  // empty: not asked for, skipped
  OutputKind kind;
};

struct NamedInput {
  std::string what;            // "the scenario", "the venue"
  std::filesystem::path path;  // empty: skipped
};

// Throws InputError naming the option, the path, what is there and what was
// expected if writing `outputs` could overwrite an input or destroy anything
// (see the rules above). `force` lets a foreign file be replaced and a
// foreign folder be written into; it never lets an input be overwritten or
// a folder be replaced.
void CheckOutputs(const std::vector<PlannedOutput>& outputs, const std::vector<NamedInput>& inputs, bool force);

// What exists at `path`, for messages: "a JSON file", "a SQLite file", "a PNG
// picture", "an empty folder", "a folder holding 3 entries (notes.txt, ...)",
// "a broken symbolic link"; "nothing" if it does not exist.
std::string DescribeExisting(const std::filesystem::path& path);

// Writes `text` to a temporary file next to `file` and renames it over `file`,
// so that an error or a kill never leaves a partial, complete-looking file.
// Removes the partial files of `file` that killed writers left, and returns
// them (for the command to say so).
std::vector<std::filesystem::path> WriteFileAtomically(const std::filesystem::path& file, const std::string& text);

// Writes `text` to `path` (a partial or staged name of the output `named`),
// flushed; throws InputError naming `named` if the file cannot be opened or
// written (a full disk). The caller removes what it leaves on an error.
void WriteWholeFile(const std::filesystem::path& path, const std::string& text, const std::filesystem::path& named);

// Writes several files that make one output (an observation's JSON and the
// series CSV it names): each is first written complete under its partial
// name, and only then are all renamed in place, in the order given; an error
// (a full disk, a folder that cannot be written) changes none of them. Only a
// kill between two renames can leave the new first file beside the old
// second one, which their readers detect (the JSON holds the CSV's SHA-256).
// Returns the killed writers' partial files it removed, as WriteFileAtomically.
std::vector<std::filesystem::path> WriteFilesAtomically(
    const std::vector<std::pair<std::filesystem::path, std::string>>& files);

// Throws InputError naming the second of two entries of `files` that are
// the same file (also through links): "B: given twice (also as A); " + why.
void RefuseRepeatedFiles(const std::vector<std::filesystem::path>& files, const std::string& why);

// Creates `dir` (and its parents) if needed; throws InputError naming it and
// the reason ("Permission denied", "File name too long", a file of that
// name) if it cannot be made -- an answer, not an internal error.
void CreateOutputFolder(const std::filesystem::path& dir);

// A temporary name next to `file` with the same extension (for writers that
// choose the format from it), to be renamed over `file` when complete.
std::filesystem::path PartialPath(const std::filesystem::path& file);

// Kinds recognised by their content.
// A JSON file whose parsed value satisfies `matches` (a marker key or value).
OutputKind JsonOutputKind(std::string name, std::function<bool(const nlohmann::json&)> matches);
// A picture: a PNG, SVG or PDF file (--picture of several commands).
OutputKind PictureOutputKind();
// A video: an MP4 or AVI file (render --video).
OutputKind VideoOutputKind();
// True if the file begins with `magic` at `offset`.
bool FileStartsWith(const std::filesystem::path& file, const std::string& magic, std::size_t offset = 0);
// A hidden partial file of PartialPath's form (".NAME.partial-PID.EXT")
// whose writing process no longer runs: what a killed writer left behind.
bool IsStalePartial(const std::filesystem::path& file);
// Removes from `folder` (not recursive) every stale partial file and every
// entry named in `leftovers` (files or folders a killed command left);
// returns what it removed, for the command to say so.
std::vector<std::filesystem::path> RemoveLeftovers(const std::filesystem::path& folder,
                                                   const std::vector<std::string>& leftovers = {});
// Removes the stale partial files of `file` (PartialPath's names for it,
// left by writers of it that were killed); returns what it removed.
std::vector<std::filesystem::path> RemoveStalePartialsOf(const std::filesystem::path& file);
// True if every entry of `folder` (not recursive) satisfies `ours`.
bool FolderHoldsOnly(const std::filesystem::path& folder,
                     const std::function<bool(const std::filesystem::directory_entry&)>& ours);

}  // namespace crowdrecon
