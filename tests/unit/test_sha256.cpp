// SHA-256 of the reports' reproducibility section: the FIPS 180-4 examples
// and a file across block boundaries, against the known digests.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "scratch.hpp"

namespace crowdrecon {
namespace {

TEST(Sha256, KnownDigests) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, AFileReadInChunksHasTheDigestOfItsBytes) {
  const std::filesystem::path file = testing::ScratchFile("a.bin");
  std::string bytes;
  for (int i = 0; i < 200000; ++i) bytes += static_cast<char>((i * 7919) & 0xff);
  std::ofstream(file, std::ios::binary) << bytes;
  EXPECT_EQ(Sha256OfFile(file), Sha256Hex(bytes));
  // Fed in odd pieces, the same digest.
  Sha256 s;
  for (std::size_t at = 0; at < bytes.size(); at += 37) s.Update(bytes.data() + at, std::min<std::size_t>(37, bytes.size() - at));
  EXPECT_EQ(s.HexDigest(), Sha256Hex(bytes));
  EXPECT_THROW(Sha256OfFile(file.parent_path() / "missing.bin"), InputError);
}

}  // namespace
}  // namespace crowdrecon
