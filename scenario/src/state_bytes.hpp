// The run-loop systems' checkpoint states as plain bytes in the machine's
// order (a checkpoint is resumed by the same build): the settle check's and
// the timeline's. A reader that runs short or finds a count out of range
// throws InputError naming whose state is damaged.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::scenario::detail {

class StateWriter {
 public:
  template <typename T>
  void Put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  template <typename T>
  void PutVector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    Put<std::uint64_t>(v.size());
    if (!v.empty()) out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void PutDoubles(const std::vector<double>& v) { PutVector(v); }
  void PutString(const std::string& s) {
    Put<std::uint64_t>(s.size());
    out += s;
  }
  std::string out;
};

class StateReader {
 public:
  // `whose` names the state in the message ("the run's settle check").
  StateReader(const std::string& in, const char* whose) : in_(in), whose_(whose) {}
  template <typename T>
  T Get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    Need(sizeof value);
    std::memcpy(&value, in_.data() + at_, sizeof value);
    at_ += sizeof value;
    return value;
  }
  // A vector of `expected` elements (any count if SIZE_MAX).
  template <typename T>
  std::vector<T> GetVector(std::size_t expected = static_cast<std::size_t>(-1)) {
    const auto n = Get<std::uint64_t>();
    if (expected != static_cast<std::size_t>(-1) && n != expected) Fail();
    if (n > (in_.size() - at_) / sizeof(T)) Fail();
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), in_.data() + at_, n * sizeof(T));  // (no null pointer to memcpy)
    at_ += n * sizeof(T);
    return v;
  }
  std::vector<double> GetDoubles(std::size_t expected = static_cast<std::size_t>(-1)) { return GetVector<double>(expected); }
  std::string GetString() {
    const auto n = Get<std::uint64_t>();
    Need(n);
    std::string s = in_.substr(at_, n);
    at_ += n;
    return s;
  }
  void Need(std::size_t bytes) const {
    if (bytes > in_.size() - at_) Fail();
  }
  bool AtEnd() const { return at_ == in_.size(); }
  [[noreturn]] void Fail() const { throw InputError(std::string("checkpoint: the state of ") + whose_ + " is damaged"); }

 private:
  const std::string& in_;
  const char* whose_;
  std::size_t at_ = 0;
};

}  // namespace crowdrecon::scenario::detail
