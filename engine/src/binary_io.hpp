// The engine's binary files, inside: an 8-byte magic, the fields in the order
// they were put, and an FNV-1a 64-bit checksum of all that. Checkpoints
// (Simulation::SaveState) and world files (world_file.hpp) are both written
// and read with these two classes; only the magic and the name in the error
// messages differ. Values are stored in the machine's byte order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/fnv.hpp"

namespace crowdrecon::engine::detail {

class BinaryWriter {
 public:
  explicit BinaryWriter(const char (&magic)[8]) { out_.append(magic, sizeof(magic)); }

  template <typename T>
  void Put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  template <typename T>
  void PutVector(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    Put(static_cast<std::uint64_t>(values.size()));
    if (!values.empty()) out_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  // Appends the checksum of everything written and hands the bytes over.
  std::string Finish() {
    Put(Fnv1a(out_.data(), out_.size()));
    return std::move(out_);
  }

 private:
  std::string out_;
};

class BinaryReader {
 public:
  // Checks the magic and the checksum of `data`, which must outlive the
  // reader. Error messages begin with `name` ("checkpoint", or a file's name)
  // and call the contents `content` ("state", "world").
  BinaryReader(const std::string& data, const char (&magic)[8], std::string name, std::string content)
      : data_(data), name_(std::move(name)), content_(std::move(content)) {
    if (data.size() < sizeof(magic) + 8 || std::memcmp(data.data(), magic, sizeof(magic)) != 0)
      throw InputError(name_ + ": not a crowdrecon engine " + content_ + " (bad magic)");
    std::uint64_t stored;
    std::memcpy(&stored, data.data() + data.size() - 8, 8);
    if (Fnv1a(data.data(), data.size() - 8) != stored)
      throw InputError(name_ + ": checksum mismatch (the file is damaged or truncated)");
    pos_ = sizeof(magic);
    end_ = data.size() - 8;
  }

  template <typename T>
  T Get() {
    static_assert(std::is_trivially_copyable_v<T>);
    if (sizeof(T) > remaining()) Truncated();
    if constexpr (std::is_same_v<T, bool>) {
      // A byte other than 0 or 1 is no bool (reading it as one is undefined).
      const unsigned char byte = static_cast<unsigned char>(data_[pos_++]);
      if (byte > 1) throw InputError(name_ + ": damaged " + content_ + " (a flag of value " + std::to_string(byte) + ")");
      return byte == 1;
    } else {
      T value;
      std::memcpy(&value, data_.data() + pos_, sizeof(T));
      pos_ += sizeof(T);
      return value;
    }
  }
  template <typename T>
  void GetVector(std::vector<T>& values, std::size_t expected_size = SIZE_MAX) {
    const auto n = Get<std::uint64_t>();
    if (expected_size != SIZE_MAX && n != expected_size)
      throw InputError(name_ + ": holds " + std::to_string(n) + " entries where this run has " +
                       std::to_string(expected_size) + " (different scenario?)");
    // Compared by division: a damaged count must not overflow n * sizeof(T)
    // into a small number and then be allocated.
    if (n > remaining() / sizeof(T)) Truncated();
    values.resize(n);
    if (n > 0) std::memcpy(values.data(), data_.data() + pos_, n * sizeof(T));
    pos_ += n * sizeof(T);
  }
  // A count of entries that each take at least `min_bytes` of what follows:
  // refused as truncation if they cannot fit, so that a damaged count never
  // makes the caller allocate more than the data could hold.
  std::size_t GetCount(std::size_t min_bytes) {
    const auto n = Get<std::uint64_t>();
    if (n > remaining() / min_bytes) Truncated();
    return static_cast<std::size_t>(n);
  }

  std::size_t remaining() const { return end_ - pos_; }
  const std::string& name() const { return name_; }

  [[noreturn]] void Truncated() const { throw InputError(name_ + ": truncated " + content_); }

 private:
  const std::string& data_;
  std::string name_, content_;
  std::size_t pos_ = 0, end_ = 0;
};

}  // namespace crowdrecon::engine::detail
