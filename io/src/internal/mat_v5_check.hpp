// A check of a MATLAB v5 file's sparse variable before libmatio reads it (io/src/mat_v5_check.cpp).
#pragma once

#include <string>

namespace dynid::internal {

/// Walks the v5 data element of the sparse variable `name` in `path` (inflating it when compressed) and returns
/// what is wrong when a sub-element's tag declares more bytes than its enclosing array holds ("" when every tag
/// fits, or when the file is not v5 or holds no such variable). libmatio allocates what the ir, jc and data tags
/// declare before reading them, so one damaged tag is a 4 GB allocation from a small file (fuzz_mat's seed).
std::string v5_sparse_damage(const std::string& path, const std::string& name);

}  // namespace dynid::internal
