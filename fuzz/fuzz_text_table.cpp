// fuzz_text_table: the input is the content of a text table (.txt/.csv/.dat/.tsv: time histories, FRFs) for
// parse_text_table, read once with a first abscissa column and once without.
#include "dynid/io/test_data.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size, [](const std::string& b) {
    try {
      dynid::parse_text_table(b, "fuzz.csv", true);
    } catch (const dynid::InputError&) {
    }
    dynid::parse_text_table(b, "fuzz.csv", false);
  });
}
