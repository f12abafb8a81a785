// The shared body of the fuzz targets: the input bytes go to one reader as a whole file. An InputError is the
// expected answer to a malformed file and is swallowed; anything else (another exception, a crash, a sanitizer
// report, a timeout, running out of memory) is a finding and reaches libFuzzer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "dynid/io/limits.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid::fuzz {

/// Smaller resource limits than a real run's, so that the fuzzer explores the parsers instead of spending its time
/// and memory building big valid models (the 612 elements of cases/frame3d-generated take seconds to finalize
/// under the sanitizers, a GENERATE set of 10^7 ids seconds to resolve, a 10^8-column matrix 800 MB).
/// Every target passes these to its reader.
inline ReaderLimits limits() {
  ReaderLimits l;
  l.max_generated_elements = 200;
  l.max_generated_ids = 100000;
  l.max_matrix_dimension = 100000;
  l.max_element_dofs = 200;
  l.max_mat_elements = 1000000;  // 8 MB per variable
  return l;
}

template <class Reader>
int feed(const std::uint8_t* data, std::size_t size, Reader read) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    read(bytes);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace dynid::fuzz
