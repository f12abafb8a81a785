// fuzz_lvm: the input is the content of a LabVIEW measurement file (.lvm, text) for parse_lvm.
#include "dynid/io/test_data.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size, [](const std::string& b) { dynid::parse_lvm(b, "fuzz.lvm"); });
}
