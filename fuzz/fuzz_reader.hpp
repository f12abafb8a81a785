// The shared body of the fuzz targets: the input bytes go to one reader as a whole file. An InputError is the
// expected answer to a malformed file and is swallowed; anything else (another exception, a crash, a sanitizer
// report, a timeout, running out of memory) is a finding and reaches libFuzzer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "dynid/mesh/error.hpp"

namespace dynid::fuzz {

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
