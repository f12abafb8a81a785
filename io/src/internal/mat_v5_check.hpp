// A check of every variable of a MATLAB v5 file when MatFile opens it (io/src/mat_v5_check.cpp). Written to protect
// libmatio, which read v5 files until 2026-11-29 and sizes its allocations by the tags; dynid's own reader
// (internal/mat_reader.hpp) reads them now, and this walk still runs first: it names the damaged variable and tag
// before anything is listed, and refuses the layouts libmatio read differently (the reasons below are libmatio's).
#pragma once

#include <string>

namespace dynid::internal {

/// The most bytes `packed` bytes of a .mat file can hold once inflated: zlib's largest ratio (about 1032:1) with a
/// margin, plus 1 MB for an uncompressed file's headers.
inline double max_inflated_bytes(double packed) { return 1100.0 * packed + 1e6; }

/// Walks the top-level data elements of the v5 file `path` (inflating compressed ones) and, in each array, the
/// tags libmatio sizes its allocations by: flags, dimensions and name; a numeric or char array's data; a sparse
/// array's ir, jc and values; a cell's or struct's nested arrays, and a struct's field names (at most 64 levels).
/// The dimensions, by which libmatio sizes an array, are checked too: a numeric or char array's data must hold
/// their values, and a cell array's cells or a struct's elements x fields (nested arrays of 8 bytes at least) must
/// fit in the array; a function handle (class 16), which libmatio reads from the variables after it, is refused.
/// Returns what is wrong with the first variable where a tag declares more bytes than its enclosing array holds or the
/// dimensions more than the data, naming it ("variable 'K': its sparse column pointers (jc) declare 4294905868 bytes
/// where the array holds 56"), or "" when every tag fits, the file ends early (libmatio reports that), or the file is
/// not v5. libmatio allocates what a tag declares before reading it, so one damaged tag is a 4 GB allocation from a
/// 364-byte file (fuzz_mat's seeds, both while listing a file's variables and while reading one). The walk reads the
/// tags as libmatio reads them (mat5.c): a layout where libmatio would read other bytes than the tags say (flags not 8
/// bytes of miUINT32, a full name tag not miINT8, dimensions or field names not whole values) is refused rather than
/// skipped, so that both read the same bytes. `unsupported` (optional) is set when the refusal is of something dynid
/// does not read rather than of damage.
std::string v5_damage(const std::string& path, bool* unsupported = nullptr);

}  // namespace dynid::internal
