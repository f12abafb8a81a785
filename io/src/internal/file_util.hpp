// Reading whole files (internal to io).
#pragma once

#include <string>

namespace dynid::internal {

/// The whole file as bytes; throws InputError("<path>: cannot open for reading") if it cannot be read.
std::string read_file_bytes(const std::string& path);

}  // namespace dynid::internal
