// Hostile files (docs/reliability.md): inputs that once made a reader hang or allocate what a file declared, and
// the fuzzers' findings (tests/data/hostile/). Each must give an InputError that says what is wrong.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "dynid/io/case_file.hpp"
#include "dynid/io/mat_file.hpp"
#include "dynid/io/matrix_market.hpp"
#include "dynid/io/mesh_files.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/output.hpp"
#include "dynid/io/uff.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

using test::ErrorOf;


using test::Slurp;

std::string Hostile(const std::string& name) { return Slurp(test::CasesDir() + "/../tests/data/hostile/" + name); }

/// The error for a Matrix Market file "m.mtx" of `text` after "%%MatrixMarket matrix coordinate real ".
std::string MatrixMarketError(const std::string& text) {
  return ErrorOf([&] { parse_matrix_market("%%MatrixMarket matrix coordinate real " + text, "m.mtx"); });
}

TEST(HostileInputs, MatrixMarketDeclaredSizes) {
  // The declared entry count does not size the allocation; the file ends first.
  EXPECT_HAS(MatrixMarketError("general\n1000 1000 1000000\n1 1 1\n"), "m.mtx:3: file ends after 1 of 1000000 entries");
  // fuzz_matrix_market: a declared 2^31 - 1 columns made the sparse matrix allocate 8 GB (a timeout).
  EXPECT_HAS(MatrixMarketError("general\n2147483647 2147483647 1\n1 1 1\n"),
             "m.mtx:2: invalid sizes 2147483647 x 2147483647, 1 entries (at most 100000000 rows and columns)");
  // fuzz_matrix_market: the mirrored entry (1, 3) of a symmetric 4 x 2 file fell outside the matrix (an Eigen
  // assertion; out-of-bounds writes without assertions).
  EXPECT_HAS(MatrixMarketError("symmetric\n4 2 1\n3 1 1\n"), "m.mtx:2: a symmetric matrix must be square, not 4 x 2");
}

TEST(HostileInputs, GmshNodeCountLargerThanTheFile) {
  const std::string e = ErrorOf([] {
    parse_gmsh("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1000000000000\n1 0 0 0\n$EndNodes\n", "big.msh");
  });
  EXPECT_HAS(e, "big.msh:5: $Nodes: number of nodes is 1000000000000, but only");
}

TEST(HostileInputs, AbaqusIncludeOfADeviceIsRefused) {
  // *INCLUDE of /dev/zero used to read forever; from memory, *INCLUDE is refused outright.
  const std::string text = "*NODE\n1, 0, 0\n*INCLUDE, INPUT=/dev/zero\n";
  EXPECT_HAS(ErrorOf([&] { parse_abaqus(text, "dev.inp", "."); }), "/dev/zero: not a regular file");
  EXPECT_HAS(ErrorOf([&] { parse_abaqus(text, "dev.inp"); }),
             "dev.inp:3: *INCLUDE: *INCLUDE is not available when the file is read from memory");
}

TEST(HostileInputs, AbaqusGenerateRange) {
  // fuzz_abaqus: a GENERATE line from -7144287 to 1 made a set of 7 x 10^6 ids (a timeout); ids are >= 1.
  EXPECT_HAS(ErrorOf([] { parse_abaqus("*NODE\n1, 0, 0\n*ELSET, ELSET=B, GENERATE\n-7144287, 1\n", "g.inp"); }),
             "g.inp:4: *ELSET, GENERATE: needs 1 <= first <= last and increment >= 1");
  EXPECT_HAS(ErrorOf([] { parse_abaqus("*NSET, NSET=A, GENERATE\n1, 2000000000, 1\n", "g.inp"); }),
             "g.inp:2: *NSET, GENERATE: more than 10^7 ids");
}

TEST(HostileInputs, CaseFileModelOfADeviceIsRefused) {
  const std::string e = ErrorOf([] { load_case("/dev/null"); });
  EXPECT_HAS(e, "/dev/null: not a regular file");
}

TEST(HostileInputs, GeneratorSizeIsCheckedBeforeBuilding) {
  const std::string e = ErrorOf([] { parse_case(Hostile("generate-huge.yaml"), "generate-huge.yaml"); });
  EXPECT_HAS(e, "generate-huge.yaml:5:");
  EXPECT_HAS(e, "generate.frame3d: 6.38e+37 elements; at most 1e+07 can be generated");
}

// Issue 17: the limits are an argument of each reader (the fuzz targets lower them), not a process-wide setting;
// the default argument gives dynid's limits to every other caller.
TEST(ReaderLimits, AreAnArgumentNotAProcessSetting) {
  ReaderLimits low;
  low.max_matrix_dimension = 2;
  low.max_generated_elements = 3;
  low.max_generated_ids = 5;
  const std::string mtx = "%%MatrixMarket matrix coordinate real general\n3 3 1\n1 1 1\n";
  EXPECT_HAS(ErrorOf([&] { parse_matrix_market(mtx, "m.mtx", low); }), "(at most 2 rows and columns)");
  EXPECT_EQ(parse_matrix_market(mtx, "m.mtx").rows(), 3);  // the lowered limits stayed with their call
  const std::string beam =
      "model:\n  materials: {steel: {E: 2.1e11, rho: 7850}}\n  sections: {b: {A: 1e-2, I: 1e-4}}\n"
      "  generate:\n    beam: {elements: 4, material: steel, section: b}\n";
  EXPECT_HAS(ErrorOf([&] { parse_case(beam, "b.yaml", ".", low); }), "4 elements; at most 3 can be generated");
  EXPECT_EQ(parse_case(beam, "b.yaml").model.elements().size(), 4u);
  ReaderLimits enough = low;
  enough.max_generated_elements = 4;
  EXPECT_EQ(parse_case(beam, "b.yaml", ".", enough).limits.max_generated_elements, 4);  // kept for its data files
  const std::string inp = "*NSET, NSET=A, GENERATE\n1, 10, 1\n";
  EXPECT_HAS(ErrorOf([&] { parse_abaqus(inp, "g.inp", "", low); }), "g.inp:2: *NSET, GENERATE: more than 5 ids");
}

TEST(HostileInputs, ModalDataNumberTooLargeForADouble) {
  // fuzz_modal_data: nlohmann's out_of_range escaped as a non-InputError exception.
  const std::string e = ErrorOf([] { parse_modal_data_json(Hostile("big-numbers.json"), "big-numbers.json"); });
  EXPECT_HAS(e, "big-numbers.json: not valid JSON: ");
  EXPECT_HAS(e, "number overflow parsing '1e400'");
}

TEST(HostileInputs, GeneratorOfEveryKindParses) {
  // fuzz_case under ASan: the generator's spec was a reference into a destroyed temporary (YAML iterator pair).
  const std::string head = "model:\n  materials: {steel: {E: 2.1e11, rho: 7850, nu: 0.3}}\n"
                           "  sections: {s: {A: 1e-2, Iy: 1e-4, Iz: 1e-4, J: 1e-6}, b: {A: 1e-2, I: 1e-4}}\n  generate:\n";
  EXPECT_EQ(parse_case(head + "    beam: {elements: 4, material: steel, section: b}\n", "b.yaml").model.elements().size(), 4u);
  EXPECT_EQ(parse_case(head + "    frame3d: {material: steel, column: s, beam: s}\n", "f.yaml").model.elements().size(), 8u);
}

TEST(HostileInputs, UffOrdinateTypeOutOfIntRange) {
  // fuzz_uff under UBSan: record 7's data type 4.2e10 was cast to int before it was checked.
  const std::string e =
      ErrorOf([] { parse_uff(Hostile("uff58b-type-out-of-range.uff"), "uff58b-type-out-of-range.uff"); });
  EXPECT_HAS(e, "uff58b-type-out-of-range.uff");
  EXPECT_HAS(e, "ordinate data type must be 2 (real single), 4 (real double), 5 (complex single) or 6 (complex double)");
}

TEST(HostileInputs, MatSparseTagLargerThanItsArray) {
  // fuzz_mat: a 364-byte v5 file whose sparse K declares 4294905868 bytes of column pointers; libmatio allocated
  // them before reading (4 GB; 26 s under ASan). Refused before libmatio reads the variable, stored as is and
  // inside a zlib stream (miCOMPRESSED: the same array element, deflated).
  const std::string seed = test::CasesDir() + "/../fuzz/corpus/fuzz_mat/damaged-sparse-4gb.mat";
  const std::string bytes = Slurp(seed);
  ASSERT_EQ(bytes.size(), 364u);
  const std::string want =
      "variable 'K': its sparse column pointers (jc) declare 4294905868 bytes where the array holds 56";
  EXPECT_HAS(ErrorOf([&] { MatFile(seed).sparse("K", "stiffness"); }), want);
  const std::string element = bytes.substr(128, 8 + 128);  // the miMATRIX element of K (tag + 128 bytes)
  std::vector<unsigned char> packed(compressBound(element.size()));
  uLongf n = packed.size();
  ASSERT_EQ(compress(packed.data(), &n, reinterpret_cast<const Bytef*>(element.data()), element.size()), Z_OK);
  std::string file = bytes.substr(0, 128);
  const std::uint32_t tag[2] = {15, static_cast<std::uint32_t>(n)};  // miCOMPRESSED, little-endian as the header says
  file.append(reinterpret_cast<const char*>(tag), 8);
  file.append(reinterpret_cast<const char*>(packed.data()), n);
  const test::ScratchDir dir("mat-sparse");
  const std::string z = dir.path("compressed.mat");
  std::ofstream(z, std::ios::binary) << file;
  EXPECT_HAS(ErrorOf([&] { MatFile(z).sparse("K", "stiffness"); }), want);
}

// The error opening fuzz_mat's seed `name` (fuzz/corpus/fuzz_mat) gives.
std::string MatSeedError(const std::string& name) {
  const std::string seed = test::CasesDir() + "/../fuzz/corpus/fuzz_mat/" + name;
  return ErrorOf([&] { MatFile{seed}; });
}

// The error opening a .mat file named `name` that holds `bytes` (written to a scratch folder).
std::string MatBytesError(const std::string& bytes, const std::string& name = "damaged.mat") {
  const test::ScratchDir dir("mat-bytes");
  const std::string path = dir.path(name);
  std::ofstream(path, std::ios::binary) << bytes;
  return ErrorOf([&] { MatFile{path}; });
}

TEST(HostileInputs, MatDamagedHeaderWhileListing) {
  // fuzz_mat (CI, 2026-11-28): a 497-byte v5 file whose double array declares 1633943556 bytes of dimensions;
  // libmatio's Mat_VarReadNextInfo allocated them while dynid listed the variables for an error message (26.6 s
  // under ASan). Every variable's tags are now checked when the file is opened.
  EXPECT_HAS(MatSeedError("damaged-dims-listing.mat"),
             "the variable at byte 128: its dimensions declare 1633943556 bytes where the array holds 337: the file is "
             "damaged");
}

TEST(HostileInputs, MatSmallElementArrayFlags) {
  // fuzz_mat (CI, 2026-11-28): a 684-byte v5 file whose array flags sit in a small element (a 32-bit tag word
  // with a size in its upper half); the walk used to stop there and leave the array to libmatio, which read on
  // into dimensions of any size (13 s under ASan). Array flags are always two words in a full tag.
  EXPECT_HAS(MatSeedError("damaged-small-array-flags.mat"),
             "the variable at byte 128: its array flags are not the two 32-bit words a MAT-file holds: the file is "
             "damaged");
}

TEST(HostileInputs, MatSmallElementDeclaringMoreThanItHolds) {
  // fuzz_mat (CI, 2026-11-28): a 317-byte v5 file whose compressed first variable has its dimensions in a small
  // element that declares 2048 bytes (a small element holds at most 4); libmatio read on to a rank of 905,969,664
  // and allocated 3.6 GB (12 s under ASan). Its flags tag has type 54, which is refused first now (libmatio leaves
  // the class empty and reads on); with its flags as miUINT32, the small element is refused by name.
  EXPECT_HAS(MatSeedError("damaged-small-element-dimensions.mat"),
             "the variable at byte 128: its array flags are not the two 32-bit words a MAT-file holds");
  EXPECT_HAS(MatSeedError("damaged-small-element-dimensions-uint32-flags.mat"),
             "the variable at byte 128: its dimensions declare 2048 bytes where a small data element holds at most 4: "
             "the file is damaged");
}

TEST(HostileInputs, MatTopLevelArrayTooSmallForItsHeader) {
  // fuzz_mat (CI, 2026-11-28): a 240-byte v5 file whose first variable is an array element of 0 bytes; libmatio
  // read on into the next element as its header, to dimensions declaring 4 GB (an 8.4 GB malloc, 15 s under
  // ASan). A top-level array takes 40 bytes at least.
  EXPECT_HAS(
      MatSeedError("damaged-empty-top-level-array.mat"),
      "the variable at byte 128: its array element declares 0 bytes, fewer than the 40 its flags, dimensions and "
      "name take: the file is damaged");
}

TEST(HostileInputs, MatV4NameLongerThanTheFile) {
  // fuzz_mat (2026-11-28): a 91-byte MATLAB v4 file whose second variable's name declares 1 GB; libmatio allocated
  // and cleared it before reading (7 s, 1 GB without ASan). v4 headers are now checked as v5 tags are.
  EXPECT_HAS(
      MatSeedError("damaged-v4-name-length.mat"),
      "the variable at byte 32: its name declares 1073741824 bytes where the file holds 39: the file is damaged");
}

TEST(HostileInputs, MatV4HeaderCheckedBeforeLibmatioOpensTheFile) {
  // fuzz_mat (2026-11-28): a file whose first word reads as a v4 type; libmatio's Mat_Open probes it as v4 and
  // allocates the name its header declares (1.4 GB, 5 s without ASan) before any check could run after it.
  EXPECT_HAS(
      MatSeedError("damaged-v4-probe-in-open.mat"),
      "the variable at byte 0: its name declares 1413565728 bytes where the file holds 353: the file is damaged");
}

TEST(HostileInputs, MatArrayFlagsDeclaringMoreThanTwoWords) {
  // fuzz_mat (2026-11-28): a 1440-byte v5 file whose third variable's flags tag declares 63 bytes. libmatio reads 8
  // bytes of flags whatever the tag says, so it read the next words as dimensions and a cell array and allocated
  // 3.8 GB (24 s under ASan), while the walk skipped the 63 bytes and checked something else.
  EXPECT_HAS(MatSeedError("damaged-flags-longer-than-8-bytes.mat"),
             "the variable at byte 1272: its array flags are not the two 32-bit words a MAT-file holds: the file is "
             "damaged");
}

TEST(HostileInputs, MatV4ByteOrderReadAsLibmatioReadsIt) {
  // fuzz_mat (2026-11-28): a 182-byte v4 file whose second type word reads as 12 only byte-swapped, with the
  // thousands digit 0 (little-endian); libmatio reads the sizes after it little-endian, the check read them swapped
  // and passed a name of 1,744,830,464 bytes (1.7 GB and 14 s without ASan).
  EXPECT_HAS(
      MatSeedError("damaged-v4-swapped-type-word.mat"),
      "the variable at byte 21: its name declares 1744830464 bytes where the file holds 141: the file is damaged");
}

TEST(HostileInputs, MatDimensionsOutOfRangeInAnEmptyArray) {
  // fuzz_mat (2026-11-28): a 32-byte v4 file declaring a 0 x -1560281086 double array. Its data (none) fit, libmatio
  // read the columns as 18446744072149270530, the element count (0) passed, and the matrix was resized to a
  // negative size (an Eigen assertion). Negative v4 dimensions are refused, and so is any one dimension beyond
  // dynid's limit even when another is 0.
  EXPECT_HAS(MatSeedError("damaged-v4-negative-columns.mat"),
             "the variable at byte 0: its dimensions 0 x -1560281086 are negative: the file is damaged");
  const test::ScratchDir dir("mat-v4-empty");
  const std::string path = dir.path("empty.mat");
  const std::int32_t header[5] = {0, 0, 2100000000, 0, 2};  // double, little-endian; 0 x 2.1e9; real; name "x"
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(header), sizeof header).write("x", 2);
  EXPECT_HAS(ErrorOf([&] { MatFile(path).matrix("x", "test"); }),
             "empty.mat: variable 'x': a 0 x 2100000000 array is larger than dynid reads");
}

// A v5 file (little-endian): the 128-byte header, then `words` (32-bit, in file order) and `data` after them.
std::string V5File(std::initializer_list<std::uint32_t> words, const std::string& data = "") {
  std::string f = "MATLAB 5.0 MAT-file, written by dynid's tests";
  f.resize(124, ' ');
  f += std::string("\x00\x01IM", 4);
  for (std::uint32_t w : words) f.append(reinterpret_cast<const char*>(&w), 4);
  return f + data;
}

// The 16 bytes of the doubles 1 and 2.
std::string OneTwo() {
  const double v[2] = {1.0, 2.0};
  return std::string(reinterpret_cast<const char*>(v), 16);
}

// A v5 file holding the cell array c = {[1 2]}; `data_bytes` is what the double's data tag declares (16 when
// intact), `cells` the cell array's second dimension and `values` the double's (1 and 2 when intact).
std::string CellFile(std::uint32_t data_bytes, std::uint32_t cells = 1, std::uint32_t values = 2) {
  // miMATRIX (14): flags (miUINT32 6, class 1 = cell), dims (miINT32 5: 1 x 1), name "c" (small miINT8 1), then
  // one cell: miMATRIX with flags (class 6 = double), dims 1 x 2, an empty name, and two doubles (miDOUBLE 9).
  return V5File({14, 112, 6, 8, 1, 0, 5, 8, 1, cells,  0x00010001, 'c',  //
                 14, 64,  6, 8, 6, 0, 5, 8, 1, values, 1,          0,   9, data_bytes},
                OneTwo());
}

TEST(HostileInputs, MatDamagedTagInsideACell) {
  const test::ScratchDir dir("mat-cell");
  const std::string good = dir.path("good.mat"), bad = dir.path("bad.mat");
  std::ofstream(good, std::ios::binary) << CellFile(16);
  std::ofstream(bad, std::ios::binary) << CellFile(0x80000000u);
  const std::vector<MatFile::Info> vars = MatFile(good).variables();  // the intact file opens and lists
  ASSERT_EQ(vars.size(), 1u);
  EXPECT_EQ(vars[0].name, "c");
  EXPECT_EQ(vars[0].type, "cell");
  EXPECT_HAS(ErrorOf([&] { MatFile{bad}; }),
             "bad.mat: variable 'c' cell 1: its real data declare 2147483648 bytes where the array holds 16: the file "
             "is damaged");
}

TEST(HostileInputs, MatEmptyCellDoesNotEndTheCheck) {
  // libmatio takes a cell whose tag's second word is 0 as empty, whatever its type, and reads the next cell; the walk
  // used to stop at such a tag and leave the next cells unchecked. c = {[], [1 2]} with the second cell's data tag
  // declaring 2 GB: refused at cell 2.
  EXPECT_HAS(MatBytesError(V5File({14, 120, 6, 8, 1, 0, 5, 8, 1, 2, 0x00010001, 'c',  //
                                   5,  0,                                             // empty cell
                                   14, 64,  6, 8, 6, 0, 5, 8, 1, 2, 1,          0,   9, 0x80000000u},
                                  OneTwo())),
             "variable 'c' cell 2: its real data declare 2147483648 bytes where the array holds 16");
}

TEST(HostileInputs, MatCellArrayReadToItsDeclaredCount) {
  // fuzz_mat (2026-11-28): an empty cell array followed by 8 more bytes inside its element. libmatio reads as many
  // cells as the dimensions declare and goes on to the next cell; the walk read the 8 bytes as a cell, stopped there
  // and left the next cell (dimensions declaring 3.5 GB, a 7 GB allocation) unchecked. c = {{}, [1 2]} with the
  // second cell's data tag declaring 2 GB: refused at cell 2.
  EXPECT_HAS(MatBytesError(V5File({14, 168, 6, 8, 1, 0, 5, 8, 1, 2, 0x00010001, 'c',  //
                                   14, 48,  6, 8, 1, 0, 5, 8, 0, 0, 1,          0,   0x00030010, 'x',
                                   14, 64,  6, 8, 6, 0, 5, 8, 1, 2, 1,          0,   9,          0x80000000u},
                                  OneTwo())),
             "variable 'c' cell 2: its real data declare 2147483648 bytes where the array holds 16");
}

TEST(HostileInputs, MatCellCountCheckedWhenTheStreamBreaksAfterTheDimensions) {
  // fuzz_mat (2026-11-28): a compressed cell array whose zlib checksum fails right after its dimensions (1 x
  // 1650614786); the walk dropped the bytes inflated with the error and stopped, libmatio used them and allocated
  // 1.65e9 cells. The inflated bytes count, and a cell array's dimensions are checked before its name.
  EXPECT_HAS(MatSeedError("damaged-cell-count-in-broken-stream.mat"),
             "the variable at byte 250: its dimensions 1 x 1650614786 declare 1650614786 cells where the array holds "
             "112 bytes, room for 14 at most: the file is damaged");
}

TEST(HostileInputs, MatNextVariableWhereLibmatioReadsIt) {
  // fuzz_mat (2026-11-28): a first variable declaring 1073 bytes; libmatio reads the next one 8 + 1073 bytes on, the
  // walk went on at the padded end (1080) and missed the function handle libmatio found there.
  EXPECT_HAS(MatSeedError("damaged-unpadded-variable-size.mat"),
             "variable 'channels' is a MATLAB function handle (array class 16), which dynid does not read");
}

TEST(HostileInputs, MatArrayCutInsideItsHeader) {
  // fuzz_mat (2026-11-28): a compressed variable whose zlib stream ends after half of its second dimension; libmatio
  // read the rest from its buffer (1 x 1650614786 cells, a 13 GB allocation) where the walk had stopped.
  EXPECT_HAS(MatSeedError("damaged-stream-cut-inside-dimensions.mat"),
             "the variable at byte 250: its data end inside its flags, dimensions and name (the file is cut short, or "
             "its compressed data are damaged)");
}

TEST(HostileInputs, MatFunctionHandleRefusedByName) {
  // fuzz_mat (2026-11-28): libmatio 1.5.23 reads a function handle's elements from the variables after it and, on a
  // damaged one, frees them with free(), leaking their contents. dynid reads no function handles: refused by name.
  EXPECT_HAS(MatBytesError(V5File({14, 40, 6, 8, 16, 0, 5, 8, 1, 1, 0x00010001, 'f'})),
             "variable 'f' is a MATLAB function handle (array class 16), which dynid does not read; save the file "
             "without it");
}

TEST(HostileInputs, MatTextOfManyEmptyRowsCountsAgainstTheLimit) {
  // fuzz_mat (2026-11-28): a cell holding a char array of 10^8 rows and no columns; its element count is 0, and
  // reading it as text made 10^8 empty strings (3.2 GB). Each row counts as one element at least.
  const test::ScratchDir dir("mat-text-rows");
  const std::string path = dir.path("rows.mat");
  std::ofstream(path, std::ios::binary) << V5File({14, 96, 6, 8, 1, 0, 5, 8, 1,       1, 0x00010001, 'c',  //
                                                   14, 48, 6, 8, 4, 0, 5, 8, 3000000, 0, 1,          0,   4, 0});
  ReaderLimits limits;
  limits.max_mat_elements = 1000000;
  EXPECT_HAS(ErrorOf([&] { MatFile(path, limits).strings("c", "channel names"); }),
             "cell 1 is a 3000000 x 0 char array, larger than dynid reads");
}

TEST(HostileInputs, MatLayoutsLibmatioReadsDifferentlyAreRefused) {
  // libmatio takes a name only from an miINT8 tag (reading on from the name's data otherwise) and dims.bytes / 4
  // dimensions: where it would read other bytes than the tags say, the walk refuses instead of skipping.
  const auto error_with = [](std::size_t offset, std::uint32_t word) {
    std::string f = CellFile(16);
    std::memcpy(f.data() + offset, &word, 4);
    return MatBytesError(f);
  };
  EXPECT_HAS(error_with(152, 6), "variable at byte 128: its dimensions are not 32-bit integers (type 6, 8 bytes)");
  EXPECT_HAS(error_with(156, 6), "variable at byte 128: its dimensions are not 32-bit integers (type 5, 6 bytes)");
  EXPECT_HAS(error_with(216, 9), "variable 'c' cell 1: its name is not text (type 9)");
}

TEST(HostileInputs, MatDimensionsDeclaringMoreThanTheDataHold) {
  // fuzz_mat (CI, 2026-11-28): libmatio allocates a cell array's cells (a pointer and a header each) by its
  // dimensions before reading any; a cell array declaring ~10^8 cells in a small file took 2 GB and 11 s to free.
  // Each cell is an array element of 8 bytes at least; a numeric array's data hold its dimensions' values.
  EXPECT_HAS(MatBytesError(CellFile(16, 100000000), "cells.mat"),
             "cells.mat: the variable at byte 128: its dimensions 1 x 100000000 declare 100000000 cells where the "
             "array holds 72 bytes, room for 9 at most: the file is damaged");  // checked before the name is read
  EXPECT_HAS(MatBytesError(CellFile(16, 1, 3), "values.mat"),
             "values.mat: variable 'c' cell 1: its dimensions 1 x 3 declare 3 values where its real data hold 16 "
             "bytes: the file is damaged");
}

namespace fs = std::filesystem;

// A fresh folder holding one earlier result, result.json ("earlier result\n"); removed afterwards.
struct ResultFolder {
  explicit ResultFolder(const std::string& tag) : scratch(tag), dir(scratch.dir()), file(scratch.path("result.json")) {
    write_file_atomic(file, "earlier result\n", false);
  }
  const test::ScratchDir scratch;
  const fs::path& dir;
  const std::string file;
};

TEST(NoDataLost, ExistingResultsAreNotOverwrittenWithoutForce) {
  const ResultFolder f("atomic");
  const fs::path& dir = f.dir;
  const std::string& file = f.file;
  EXPECT_HAS(ErrorOf([&] { write_file_atomic(file, "new", false); }), "result.json: file exists; pass --force");
  EXPECT_EQ(Slurp(file), "earlier result\n");
  EXPECT_HAS(ErrorOf([&] { refuse_existing({(dir / "other.png").string(), file}, false); }), "result.json: file exists");
  write_file_atomic(file, "replaced\n", true);
  EXPECT_EQ(Slurp(file), "replaced\n");
  EXPECT_HAS(ErrorOf([&] { write_file_atomic((dir / "no-such-folder" / "r.json").string(), "x", true); }),
             "does not exist");
  // No temporary file is left behind by a finished write.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) entries += e.is_regular_file();
  EXPECT_EQ(entries, 1);
}

TEST(NoDataLost, AKilledWriteLeavesTheEarlierFileWhole) {
  // A child process replaces a file with 400 MB and is killed (SIGKILL: no clean-up runs) while it writes. The
  // file then holds either the earlier content or the whole new one, never a part (temp file + rename).
  const ResultFolder f("kill");
  const std::string& file = f.file;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      write_file_atomic(file, std::string(400u << 20, 'x'), true);
    } catch (...) {
    }
    ::_exit(0);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  const auto size = fs::file_size(file);
  EXPECT_TRUE(size == 15 || size == (400u << 20)) << size << " bytes";
  if (size == 15) {
    EXPECT_EQ(Slurp(file), "earlier result\n");
  }
}

}  // namespace
}  // namespace dynid
