// dynid/io/matrix_market.hpp -- Matrix Market (coordinate, real) files: exchange of K and M with other codes.
#pragma once

#include <string>

#include "dynid/io/limits.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// Writes A in Matrix Market coordinate format, "real symmetric" (lower triangle) or "real general".
/// 17 significant digits, so that a read-back is bitwise identical. Written atomically; refuses to replace an
/// existing file unless `overwrite`.
void write_matrix_market(const std::string& path, const SparseMatrix& A, bool symmetric, bool overwrite);

/// Reads a Matrix Market "coordinate real|integer general|symmetric" file into full (both-triangle) storage.
/// Duplicate entries are summed. Errors name the file and line. Sizes beyond `limits.max_matrix_dimension` are
/// refused.
SparseMatrix read_matrix_market(const std::string& path, const ReaderLimits& limits = {});
/// The same, from a file's content held in memory; `name` names it in messages.
SparseMatrix parse_matrix_market(const std::string& text, const std::string& name, const ReaderLimits& limits = {});

}  // namespace dynid
