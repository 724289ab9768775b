// The `main` of a fuzz harness built without libFuzzer (GCC, the normal
// build): runs LLVMFuzzerTestOneInput once over every file named, and over
// every file of every folder named (sorted, so runs repeat), as libFuzzer
// does when given files and -runs=0. A folder that does not exist is skipped
// (a harness whose regression folder is still empty has none in git). A
// crash is a crash here too; the ctest tests fuzz.replay.* run this over
// fuzz/corpus/HARNESS and fuzz/regressions/HARNESS.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::filesystem::path> InputsOf(const std::filesystem::path& arg) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(arg)) {
    for (const auto& entry : std::filesystem::directory_iterator(arg))
      if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
  } else if (std::filesystem::exists(arg)) {
    files.push_back(arg);
  } else {
    std::printf("%s: not found, skipped\n", arg.string().c_str());
  }
  return files;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t count = 0;
  for (int i = 1; i < argc; ++i) {
    for (const auto& file : InputsOf(argv[i])) {
      std::ifstream in(file, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      std::printf("%s (%zu bytes)\n", file.string().c_str(), bytes.size());
      std::fflush(stdout);  // the input a crash happens on is the last line shown
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      ++count;
    }
  }
  std::printf("replayed %zu inputs\n", count);
  return count > 0 ? 0 : 1;
}
