// A scratch file of the running test. ctest runs each test of a binary as a
// process of its own, several at once, and tests write files of the same name
// (a picture, a body file): each test gets a folder of its own, named after
// the suite, the test and the process. The folder is removed when its test
// passes and kept when it fails, to look at (before, every folder stayed:
// each run of the suite left some 1,400 behind in the temporary folder).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>
#include <string>
#include <system_error>
#include <utility>

namespace crowdrecon::testing {

namespace detail {

// Removes a test's scratch folder at the end of that test, if it passed.
class ScratchCleaner : public ::testing::EmptyTestEventListener {
 public:
  ScratchCleaner(std::string test, std::filesystem::path dir) : test_(std::move(test)), dir_(std::move(dir)) {}
  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (std::string(info.test_suite_name()) + "." + info.name() != test_ || !info.result()->Passed()) return;
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

 private:
  std::string test_;
  std::filesystem::path dir_;
};

}  // namespace detail

inline std::filesystem::path ScratchFile(const std::string& name) {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string who = test ? std::string(test->test_suite_name()) + "." + test->name() : "none";
  const auto dir = std::filesystem::temp_directory_path() / ("crowdrecon_test-" + who + "-" + std::to_string(::getpid()));
  static std::set<std::string> cleaned;  // the tests whose folder has its cleaner
  std::filesystem::create_directories(dir);
  if (test && cleaned.insert(who).second)  // gtest owns (and deletes) the listener
    ::testing::UnitTest::GetInstance()->listeners().Append(new detail::ScratchCleaner(who, dir));
  return dir / name;
}

}  // namespace crowdrecon::testing
