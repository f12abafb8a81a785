// fuzz_uff: the input is the content of a Universal File (ASCII and binary datasets 58/58b, 55, 15, 2411, 2412,
// 164, others skipped) for parse_uff.
#include "dynid/io/uff.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size, [](const std::string& b) { dynid::parse_uff(b, "fuzz.uff"); });
}
