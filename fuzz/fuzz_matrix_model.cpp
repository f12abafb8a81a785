// fuzz_matrix_model: the readers of a matrix model (docs/matrix-input.md). The first byte picks the reader
// (mod 3: element matrices on 60 equations, DOF table, node table); the rest is the file's content.
#include "dynid/io/matrix_model.hpp"
#include "fuzz_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int which = data[0] % 3;
  return dynid::fuzz::feed(data + 1, size - 1, [which](const std::string& b) {
    if (which == 0)
      dynid::parse_element_matrices(b, "fuzz.txt", 60, dynid::fuzz::limits());
    else if (which == 1)
      dynid::parse_dof_table(b, "fuzz.csv");
    else
      dynid::parse_node_table(b, "fuzz.csv");
  });
}
