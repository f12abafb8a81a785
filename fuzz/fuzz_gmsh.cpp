// fuzz_gmsh: the input is the content of a Gmsh .msh file (MSH 2.2 or 4.1, ASCII or binary) for parse_gmsh.
#include "dynid/io/mesh_files.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size, [](const std::string& b) { dynid::parse_gmsh(b, "fuzz.msh"); });
}
