// fuzz_case: the input is the text of a case file (YAML, with model, analysis, detect, update and test sections)
// for parse_case. Its folder does not exist, so files it names by relative path (mesh, model and measured data
// files) are not found: that is an InputError, and the fuzzer stays on the case file itself (the other readers
// have their own targets). The fuzz targets lower the reader limits (fuzz_reader.hpp): `generate:` builds at most
// 200 elements.
#include "dynid/io/case_file.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size, [](const std::string& b) {
    dynid::parse_case(b, "fuzz.yaml", "/nonexistent/dynid-fuzz", dynid::fuzz::limits());
  });
}
