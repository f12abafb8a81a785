// fuzz_modal_data: the input is the content of a measured modal data JSON file for parse_modal_data_json.
#include "dynid/io/modal_data_io.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size, [](const std::string& b) { dynid::parse_modal_data_json(b, "fuzz.json"); });
}
