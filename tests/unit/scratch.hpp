// A scratch file of the running test. ctest runs each test of a binary as a
// process of its own, several at once, and tests write files of the same name
// (a picture, a body file): each test gets a folder of its own, named after
// the suite, the test and the process.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace crowdrecon::testing {

inline std::filesystem::path ScratchFile(const std::string& name) {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string who = test ? std::string(test->test_suite_name()) + "." + test->name() : "none";
  const auto dir = std::filesystem::temp_directory_path() / ("crowdrecon_test-" + who + "-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

}  // namespace crowdrecon::testing
