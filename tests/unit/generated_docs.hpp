// A table in the docs generated from the code: the text between
//   <!-- NAME: generated from FUNCTION -->   and   <!-- /NAME -->
// of FILE must equal `generated`. With CROWDRECON_UPDATE_DOCS=1 the file is
// rewritten instead (and the test skipped).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace crowdrecon::testing {

inline void ExpectGeneratedSection(const std::string& relative_file, const std::string& name,
                                   const std::string& function, const std::string& generated) {
  const std::string file = std::string(CROWDRECON_SOURCE_DIR) + "/" + relative_file;
  std::ifstream in(file);
  ASSERT_TRUE(in) << relative_file;
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string doc = buffer.str();
  const std::string begin = "<!-- " + name + ": generated from " + function + " -->\n";
  const std::string end = "<!-- /" + name + " -->";
  const std::size_t a = doc.find(begin), b = doc.find(end);
  ASSERT_NE(a, std::string::npos) << relative_file << " has no line " << begin;
  ASSERT_NE(b, std::string::npos) << relative_file << " has no line " << end;
  const std::string in_doc = doc.substr(a + begin.size(), b - a - begin.size());
  if (const char* update = std::getenv("CROWDRECON_UPDATE_DOCS"); update && std::string(update) == "1") {
    std::ofstream(file, std::ios::binary) << doc.substr(0, a + begin.size()) << generated << doc.substr(b);
    GTEST_SKIP() << relative_file << " updated";
  }
  EXPECT_EQ(in_doc, generated) << relative_file << "'s " << name << " differs from " << function
                               << "; replace it with the text above (or set CROWDRECON_UPDATE_DOCS=1)";
}

}  // namespace crowdrecon::testing
