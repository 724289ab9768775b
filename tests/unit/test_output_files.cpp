// Outputs replaced as a whole (issue 40): several files written together
// (WriteFilesAtomically: an observation's JSON and CSV) and a folder output
// staged beside the folder (StagedFolder: a report). An error before the
// end changes nothing of a previous output; a kill leaves a staging folder
// that the next writer removes and reports; Ctrl-C removes it at once.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/staged_folder.hpp"
#include "scratch.hpp"

namespace crowdrecon {
namespace {

namespace fs = std::filesystem;

std::string ReadStaged(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void WriteStaged(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

// Entries of `folder`, names sorted, joined by spaces.
std::string StagedEntries(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(folder)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : " ") + n;
  return s;
}

// Scratch folder PARENT/name holding `files` (name, text); returns it.
fs::path FolderWith(const std::string& scratch, const std::string& name,
                    const std::vector<std::pair<std::string, std::string>>& files) {
  const fs::path out = testing::ScratchFile(scratch) / name;
  fs::create_directories(out);
  for (const auto& [file, text] : files) WriteStaged(out / file, text);
  return out;
}

// A folder kind recognised by a marker file, as a report's by its report.html.
OutputKind MarkedStagedKind() {
  return {"a marked folder", true, [](const fs::path& dir) { return fs::exists(dir / "report.html"); }};
}

TEST(OutputFiles, SeveralFilesAreReplacedTogetherOrNotAtAll) {
  const fs::path dir = testing::ScratchFile("pair");
  fs::create_directories(dir);
  WriteStaged(dir / "obs.csv", "old series");
  WriteStaged(dir / "obs.json", "old json");
  // The second file cannot be written (its folder does not exist): the
  // first, complete under its partial name, is not put in place either.
  EXPECT_THROW(WriteFilesAtomically({{dir / "obs.csv", "new series"}, {dir / "missing" / "obs.json", "new json"}}),
               InputError);
  EXPECT_EQ(ReadStaged(dir / "obs.csv"), "old series");
  EXPECT_EQ(StagedEntries(dir), "obs.csv obs.json") << "no partial file left";
  // Both written: both replaced; a killed writer's partial file removed and returned.
  WriteStaged(dir / ".obs.partial-999999999.json", "a killed writer's");
  const std::vector<fs::path> removed = WriteFilesAtomically({{dir / "obs.csv", "new series"}, {dir / "obs.json", "new json"}});
  EXPECT_EQ(ReadStaged(dir / "obs.csv"), "new series");
  EXPECT_EQ(ReadStaged(dir / "obs.json"), "new json");
  ASSERT_EQ(removed.size(), 1u);
  EXPECT_EQ(removed[0].filename(), ".obs.partial-999999999.json");
  EXPECT_EQ(StagedEntries(dir), "obs.csv obs.json");
}

TEST(StagedFolder, ANewFolderAppearsOnlyWhenComplete) {
  const fs::path parent = testing::ScratchFile("new"), out = parent / "report";
  StagedFolder staged(out, MarkedStagedKind());
  staged.Write("people.csv", "a");
  staged.Write("report.html", "b");
  EXPECT_FALSE(fs::exists(out));
  staged.Commit();
  EXPECT_EQ(StagedEntries(out), "people.csv report.html");
  EXPECT_EQ(StagedEntries(parent), "report") << "no staging folder left";
}

TEST(StagedFolder, APreviousOutputIsReplacedAsAWhole) {
  const fs::path out = FolderWith("previous", "report",
                                  {{"report.html", "old page"}, {"report.pdf", "old pdf"}, {"people.csv", "old people"}});
  const fs::path parent = out.parent_path();
  {
    // Given with a trailing separator, as a shell completes it.
    StagedFolder staged(out.string() + "/", MarkedStagedKind());
    staged.Write("report.html", "new page");
    staged.Write("people.csv", "new people");
    EXPECT_EQ(ReadStaged(out / "people.csv"), "old people") << "untouched until Commit";
    staged.Commit();
  }
  EXPECT_EQ(StagedEntries(out), "people.csv report.html") << "the old PDF, made with other options, went with its folder";
  EXPECT_EQ(ReadStaged(out / "report.html"), "new page");
  EXPECT_EQ(StagedEntries(parent), "report");
}

TEST(StagedFolder, AnErrorBeforeCommitLeavesThePreviousOutputAsItWas) {
  const fs::path out = FolderWith("error", "report", {{"report.html", "old page"}, {"people.csv", "old people"}});
  const fs::path parent = out.parent_path();
  try {
    StagedFolder staged(out, MarkedStagedKind());
    staged.Write("people.csv", "new people");
    throw InputError("the browser could not print");  // as report.pdf failing
  } catch (const InputError&) {
  }
  EXPECT_EQ(ReadStaged(out / "people.csv"), "old people");
  EXPECT_EQ(StagedEntries(out), "people.csv report.html");
  EXPECT_EQ(StagedEntries(parent), "report") << "the staging folder removed";
}

TEST(StagedFolder, AForeignFolderReceivesTheFilesAndKeepsItsOwn) {
  const fs::path out = FolderWith("foreign", "notes", {{"mine.txt", "the user's"}, {"people.csv", "old people"}});
  const fs::path parent = out.parent_path();
  StagedFolder staged(out, MarkedStagedKind());
  staged.Write("people.csv", "new people");
  staged.Write("report.html", "page");
  staged.Commit();
  EXPECT_EQ(StagedEntries(out), "mine.txt people.csv report.html");
  EXPECT_EQ(ReadStaged(out / "mine.txt"), "the user's");
  EXPECT_EQ(ReadStaged(out / "people.csv"), "new people");
  EXPECT_EQ(StagedEntries(parent), "notes");
}

TEST(StagedFolder, AKilledWritersStagingFolderIsRemovedAndSaid) {
  const fs::path parent = testing::ScratchFile("killed"), out = parent / "report";
  fs::create_directories(parent / ".report.partial-999999999" / ".chromium-profile");
  WriteStaged(parent / ".report.partial-999999999" / "people.csv", "half");
  StagedFolder staged(out, MarkedStagedKind());
  ASSERT_EQ(staged.removed().size(), 1u);
  EXPECT_EQ(staged.removed()[0].filename(), ".report.partial-999999999");
  staged.Write("report.html", "page");
  staged.Commit();
  EXPECT_EQ(StagedEntries(parent), "report");
}

TEST(StagedFolder, CtrlCRemovesTheStagingFolderAndStillEndsTheProgram) {
  const fs::path out = FolderWith("interrupted", "report", {{"report.html", "old page"}});
  const fs::path parent = out.parent_path();
  for (int signal : {SIGINT, SIGTERM}) {
    const pid_t pid = fork();
    if (pid == 0) {
      StagedFolder staged(out, MarkedStagedKind());
      staged.Write("people.csv", "new people");
      staged.Write("report.html", "new page");
      std::raise(signal);
      _exit(0);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(WTERMSIG(status), signal);
    EXPECT_EQ(StagedEntries(parent), "report") << strsignal(signal);
    EXPECT_EQ(ReadStaged(out / "report.html"), "old page");
  }
}

}  // namespace
}  // namespace crowdrecon
