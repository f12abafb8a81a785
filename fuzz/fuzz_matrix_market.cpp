// fuzz_matrix_market: the input is the content of a Matrix Market file for parse_matrix_market.
#include "dynid/io/matrix_market.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(
      data, size, [](const std::string& b) { dynid::parse_matrix_market(b, "fuzz.mtx", dynid::fuzz::limits()); });
}
