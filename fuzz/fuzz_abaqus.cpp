// fuzz_abaqus: the input is the content of an Abaqus .inp file for parse_abaqus, read from memory: *INCLUDE is
// refused (an InputError), so the result depends on the input alone.
#include "dynid/io/mesh_files.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size,
                           [](const std::string& b) { dynid::parse_abaqus(b, "fuzz.inp", "", dynid::fuzz::limits()); });
}
