// dynid's MATLAB v5 and v4 readers (io/src/mat_v5_reader.cpp, mat_v4_reader.cpp) against libmatio, the reader
// dynid used for them before and still uses for v7.3: files written by libmatio itself (every class dynid reads;
// v5 stored and compressed, and v4) and the real MATLAB files of ../shared are read by both, and every value must
// agree exactly (the same stored numbers converted to double: tolerance 0). Layouts neither SciPy nor libmatio writes
// here are built by hand: big-endian files, and text in UTF-16 and UTF-32.
#include <gtest/gtest.h>
#include <matio.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "dynid/io/mat_file.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

struct MatClose {
  void operator()(mat_t* m) const { Mat_Close(m); }
};
struct VarFree {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using MatPtr = std::unique_ptr<mat_t, MatClose>;
using VarPtr = std::unique_ptr<matvar_t, VarFree>;

double ValueOf(const void* p, matio_types t, std::size_t k) {
  switch (t) {
    case MAT_T_INT8:
      return static_cast<const std::int8_t*>(p)[k];
    case MAT_T_UINT8:
      return static_cast<const std::uint8_t*>(p)[k];
    case MAT_T_INT16:
      return static_cast<const std::int16_t*>(p)[k];
    case MAT_T_UINT16:
      return static_cast<const std::uint16_t*>(p)[k];
    case MAT_T_INT32:
      return static_cast<const std::int32_t*>(p)[k];
    case MAT_T_UINT32:
      return static_cast<const std::uint32_t*>(p)[k];
    case MAT_T_SINGLE:
      return static_cast<const float*>(p)[k];
    case MAT_T_DOUBLE:
      return static_cast<const double*>(p)[k];
    case MAT_T_INT64:
      return static_cast<double>(static_cast<const std::int64_t*>(p)[k]);
    case MAT_T_UINT64:
      return static_cast<double>(static_cast<const std::uint64_t*>(p)[k]);
    default:
      ADD_FAILURE() << "unexpected matio type " << t;
      return 0;
  }
}

// Writes `bytes` to file `name` of `dir`; returns its path.
std::string WriteBytes(const test::ScratchDir& dir, const std::string& name, const std::string& bytes) {
  const std::string path = dir.path(name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// Compares every variable dynid lists in `path` with what libmatio reads; returns how many values were compared.
std::size_t CompareWithLibmatio(const std::string& path) {
  SCOPED_TRACE(path);
  const MatFile f(path);
  const MatPtr m(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  EXPECT_TRUE(m) << "libmatio cannot open it";
  if (!m) return 0;
  std::size_t compared = 0;
  std::vector<std::string> names;
  for (const MatFile::Info& info : f.variables()) {
    SCOPED_TRACE(info.name);
    names.push_back(info.name);
    Mat_Rewind(m.get());
    const VarPtr v(Mat_VarRead(m.get(), info.name.c_str()));
    if (!v) {
      ADD_FAILURE() << "libmatio cannot read it";
      continue;
    }
    std::vector<std::size_t> dims(v->dims, v->dims + v->rank);
    EXPECT_EQ(info.dims, dims);
    EXPECT_EQ(info.complex, v->isComplex != 0);
    if (v->isComplex) continue;
    if (v->class_type == MAT_C_SPARSE) {
      const auto* s = static_cast<const mat_sparse_t*>(v->data);
      const Eigen::MatrixXd A = f.matrix(info.name, "test");
      Eigen::MatrixXd B = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1]));
      for (std::size_t j = 0; j + 1 < s->njc; ++j)
        for (auto k = s->jc[j]; k < s->jc[j + 1]; ++k)
          B(s->ir[k], static_cast<Eigen::Index>(j)) += ValueOf(s->data, v->data_type, k);
      EXPECT_EQ((A - B).cwiseAbs().maxCoeff(), 0.0);
      compared += s->ndata;
    } else if (v->class_type >= MAT_C_DOUBLE && v->class_type <= MAT_C_UINT64 && v->rank == 2) {
      const Eigen::MatrixXd A = f.matrix(info.name, "test");
      for (Eigen::Index k = 0; k < A.size(); ++k)
        EXPECT_EQ(A(k), ValueOf(v->data, v->data_type, static_cast<std::size_t>(k))) << "value " << k;
      compared += static_cast<std::size_t>(A.size());
    } else if (v->class_type == MAT_C_CHAR && v->rank == 2 && v->data_size == 1) {
      const std::vector<std::string> text = f.strings(info.name, "test");
      EXPECT_EQ(text.size(), dims[0]);
      if (text.size() != dims[0]) continue;
      for (std::size_t i = 0; i < dims[0]; ++i) {
        std::string s;
        for (std::size_t j = 0; j < dims[1]; ++j) s += static_cast<const char*>(v->data)[i + j * dims[0]];
        EXPECT_EQ(text[i], s.substr(0, s.find_last_not_of(' ') + 1));
      }
      compared += dims[0] * dims[1];
    } else if (v->class_type == MAT_C_CELL) {
      const std::size_t cells = v->nbytes / v->data_size;
      std::vector<Eigen::MatrixXd> got;
      try {
        got = f.matrices(info.name, "test");
      } catch (const InputError&) {  // a cell array of text: compared as text
        EXPECT_EQ(f.strings(info.name, "test").size(), cells);
        continue;
      }
      EXPECT_EQ(got.size(), cells);
      if (got.size() != cells) continue;
      for (std::size_t c = 0; c < cells; ++c) {
        const matvar_t* x = Mat_VarGetCell(v.get(), static_cast<int>(c));
        for (Eigen::Index k = 0; k < got[c].size(); ++k)
          EXPECT_EQ(got[c](k), ValueOf(x->data, x->data_type, static_cast<std::size_t>(k))) << "cell " << c;
        compared += static_cast<std::size_t>(got[c].size());
      }
    }
  }
  // libmatio lists the same variables in the same order.
  std::vector<std::string> theirs;
  Mat_Rewind(m.get());
  while (matvar_t* v = Mat_VarReadNextInfo(m.get())) {
    theirs.emplace_back(v->name ? v->name : "");
    Mat_VarFree(v);
  }
  EXPECT_EQ(names, theirs);
  return compared;
}

// Writes the real sparse matrix `name` (rows x cols; 0-based row indices `ir`, column pointers `jc`) with libmatio.
void PutSparse(mat_t* m, const char* name, std::size_t rows, std::size_t cols, std::vector<mat_uint32_t> ir,
               std::vector<mat_uint32_t> jc, std::vector<double> values, matio_compression z) {
  mat_sparse_t sparse{};
  sparse.nzmax = sparse.nir = sparse.ndata = static_cast<mat_uint32_t>(values.size());
  sparse.ir = ir.data();
  sparse.jc = jc.data();
  sparse.njc = static_cast<mat_uint32_t>(jc.size());
  sparse.data = values.data();
  std::size_t dims[2] = {rows, cols};
  matvar_t* v = Mat_VarCreate(name, MAT_C_SPARSE, MAT_T_DOUBLE, 2, dims, &sparse, MAT_F_DONT_COPY_DATA);
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(Mat_VarWrite(m, v, z), 0);
  v->data = nullptr;  // the arrays are this function's
  Mat_VarFree(v);
}

// Writes with libmatio a v5 file holding every class dynid reads.
void WriteWithLibmatio(const std::string& path, matio_compression compression) {
  const MatPtr m(Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5));
  ASSERT_TRUE(m);
  const auto put = [&](matvar_t* v) {
    ASSERT_NE(v, nullptr);
    EXPECT_EQ(Mat_VarWrite(m.get(), v, compression), 0);
    Mat_VarFree(v);
  };
  std::size_t d23[2] = {2, 3}, d15[2] = {1, 5}, d11[2] = {1, 1}, d00[2] = {0, 0}, d12[2] = {1, 2};
  double a[6] = {1.5, -2, 3e-300, 4e300, 0, -0.25};
  put(Mat_VarCreate("a", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d23, a, 0));
  float f[5] = {1.25f, -7, 3.5e30f, 0, 1e-30f};
  put(Mat_VarCreate("f", MAT_C_SINGLE, MAT_T_SINGLE, 2, d15, f, 0));
  std::int8_t i8[5] = {-128, -1, 0, 1, 127};
  put(Mat_VarCreate("i8", MAT_C_INT8, MAT_T_INT8, 2, d15, i8, 0));
  std::uint16_t u16[5] = {0, 1, 2, 65535, 300};
  put(Mat_VarCreate("u16", MAT_C_UINT16, MAT_T_UINT16, 2, d15, u16, 0));
  std::int32_t i32[5] = {-2147483647 - 1, -5, 0, 7, 2147483647};
  put(Mat_VarCreate("i32", MAT_C_INT32, MAT_T_INT32, 2, d15, i32, 0));
  std::int64_t i64[5] = {-9007199254740992LL, -1, 0, 1, 9007199254740992LL};
  put(Mat_VarCreate("i64", MAT_C_INT64, MAT_T_INT64, 2, d15, i64, 0));
  std::uint64_t u64[5] = {0, 1, 2, 3, 18446744073709551615ULL};
  put(Mat_VarCreate("u64", MAT_C_UINT64, MAT_T_UINT64, 2, d15, u64, 0));
  std::uint8_t l[5] = {1, 0, 1, 1, 0};
  put(Mat_VarCreate("l", MAT_C_UINT8, MAT_T_UINT8, 2, d15, l, MAT_F_LOGICAL));
  put(Mat_VarCreate("e", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d00, nullptr, 0));
  double s1 = 42;
  put(Mat_VarCreate("s", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d11, &s1, 0));
  char text[] = "1u2u3r";  // 2 x 3: "123" and "uur" read column-major
  put(Mat_VarCreate("t", MAT_C_CHAR, MAT_T_UINT8, 2, d23, text, 0));
  // A 3 x 3 sparse matrix with an empty column: (1,1) 4, (3,1) -1, (2,3) 2.5.
  PutSparse(m.get(), "K", 3, 3, {0, 2, 1}, {0, 2, 2, 3}, {4, -1, 2.5}, compression);
  // A cell array of two matrices: libmatio frees the cells with the cell array.
  double c1[2] = {1, 2}, c2[1] = {3};
  matvar_t* cells[2] = {Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d12, c1, 0),
                        Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d11, c2, 0)};
  put(Mat_VarCreate("c", MAT_C_CELL, MAT_T_CELL, 2, d12, cells, 0));
}

TEST(MatV5Reader, AgreesWithLibmatioOnFilesLibmatioWrote) {
  const test::ScratchDir dir("mat-v5-libmatio");
  for (const matio_compression z : {MAT_COMPRESSION_NONE, MAT_COMPRESSION_ZLIB}) {
    const std::string path = dir.path(z == MAT_COMPRESSION_NONE ? "stored.mat" : "compressed.mat");
    WriteWithLibmatio(path, z);
    EXPECT_EQ(CompareWithLibmatio(path), 6u + 5 * 7 + 1 + 6 + 3 + 3);  // a, f ... l, s, t, K's nonzeros, c
    const MatFile f(path);
    EXPECT_EQ(f.version(), "MATLAB 5.0 (v5/v7)");
    EXPECT_EQ(f.strings("t", "text"), (std::vector<std::string>{"123", "uur"}));
    EXPECT_EQ(f.variables()[7].type, "logical");
    const SparseMatrix K = f.sparse("K", "stiffness");
    EXPECT_EQ(K.nonZeros(), 3);
    EXPECT_EQ(K.coeff(2, 0), -1.0);
    EXPECT_EQ(K.coeff(1, 2), 2.5);
  }
}

// Writes with libmatio a v4 file holding every class v4 has: numeric matrices of its six precisions, text and a
// sparse matrix.
void WriteV4WithLibmatio(const std::string& path) {
  const MatPtr m(Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT4));
  ASSERT_TRUE(m);
  const auto put = [&](matvar_t* v) {
    ASSERT_NE(v, nullptr);
    EXPECT_EQ(Mat_VarWrite(m.get(), v, MAT_COMPRESSION_NONE), 0);
    Mat_VarFree(v);
  };
  std::size_t d23[2] = {2, 3}, d15[2] = {1, 5}, d00[2] = {0, 0};
  double a[6] = {1.5, -2, 3e-300, 4e300, 0, -0.25};
  put(Mat_VarCreate("a", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d23, a, 0));
  float f[5] = {1.25f, -7, 3.5e30f, 0, 1e-30f};
  put(Mat_VarCreate("f", MAT_C_SINGLE, MAT_T_SINGLE, 2, d15, f, 0));
  std::int32_t i32[5] = {-2147483647 - 1, -5, 0, 7, 2147483647};
  put(Mat_VarCreate("i32", MAT_C_INT32, MAT_T_INT32, 2, d15, i32, 0));
  std::int16_t i16[5] = {-32768, -1, 0, 1, 32767};
  put(Mat_VarCreate("i16", MAT_C_INT16, MAT_T_INT16, 2, d15, i16, 0));
  std::uint16_t u16[5] = {0, 1, 2, 65535, 300};
  put(Mat_VarCreate("u16", MAT_C_UINT16, MAT_T_UINT16, 2, d15, u16, 0));
  std::uint8_t u8[5] = {0, 1, 128, 255, 7};
  put(Mat_VarCreate("u8", MAT_C_UINT8, MAT_T_UINT8, 2, d15, u8, 0));
  put(Mat_VarCreate("e", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d00, nullptr, 0));
  char text[] = "1u2u3r";
  put(Mat_VarCreate("t", MAT_C_CHAR, MAT_T_UINT8, 2, d23, text, 0));
  PutSparse(m.get(), "K", 3, 3, {0, 2, 1}, {0, 2, 2, 3}, {4, -1, 2.5}, MAT_COMPRESSION_NONE);
}

TEST(MatV4Reader, AgreesWithLibmatioOnFilesLibmatioWrote) {
  const test::ScratchDir dir("mat-v4-libmatio");
  const std::string path = dir.path("v4.mat");
  WriteV4WithLibmatio(path);
  EXPECT_EQ(CompareWithLibmatio(path), 6u + 5 * 5 + 6 + 3);  // a, f ... u8, t, K's nonzeros
  const MatFile f(path);
  EXPECT_EQ(f.version(), "MATLAB 4");
  EXPECT_EQ(f.strings("t", "text"), (std::vector<std::string>{"123", "uur"}));
  const SparseMatrix K = f.sparse("K", "stiffness");
  EXPECT_EQ(K.nonZeros(), 3);
  EXPECT_EQ(K.coeff(2, 0), -1.0);
  EXPECT_EQ(K.coeff(1, 2), 2.5);
}

TEST(MatV4Reader, BigEndianAndUnsortedSparse) {
  // v4 files written on a big-endian machine (type word 1000 + ...): x = [1 2; 3 4], and a 3 x 2 sparse matrix whose
  // entries are stored out of column order (as a v4 file may hold them): (2,2) 5, (1,1) 6, (3,1) 7.
  const test::ScratchDir dir("mat-v4-endian");
  for (const bool big : {false, true}) {
    SCOPED_TRACE(big ? "big-endian" : "little-endian");
    std::string bytes;
    const auto put = [&](std::int32_t type, std::int32_t rows, std::int32_t cols, const std::vector<double>& values) {
      const std::int32_t header[5] = {type + (big ? 1000 : 0), rows, cols, 0, 2};
      for (std::int32_t w : header) {
        auto u = static_cast<std::uint32_t>(w);
        if (big) u = __builtin_bswap32(u);
        bytes.append(reinterpret_cast<const char*>(&u), 4);
      }
      bytes += std::string(1, type == 0 ? 'x' : 'S') + '\0';
      for (double d : values) {
        std::uint64_t u;
        std::memcpy(&u, &d, 8);
        if (big) u = __builtin_bswap64(u);
        bytes.append(reinterpret_cast<const char*>(&u), 8);
      }
    };
    put(0, 2, 2, {1, 3, 2, 4});
    put(2, 4, 3, {2, 1, 3, 3, /* j */ 2, 1, 1, 2, /* values */ 5, 6, 7, 0});
    const MatFile f(WriteBytes(dir, big ? "big.mat" : "little.mat", bytes));
    EXPECT_EQ(f.version(), "MATLAB 4");
    const Eigen::MatrixXd x = f.matrix("x", "test");
    EXPECT_EQ(x(0, 1), 2.0);
    EXPECT_EQ(x(1, 0), 3.0);
    const std::vector<MatFile::Info> vars = f.variables();
    ASSERT_EQ(vars.size(), 2u);
    EXPECT_EQ(vars[1].dims, (std::vector<std::size_t>{3, 2}));
    const Eigen::MatrixXd S = f.matrix("S", "test");
    Eigen::MatrixXd want(3, 2);
    want << 6, 0, 0, 5, 7, 0;
    EXPECT_EQ(S, want);
  }
}

TEST(MatFileLimits, ASparseMatrixCountsItsRowsAndColumnsNotItsDenseSize) {
  // A 100,000-DOF sparse stiffness matrix has 10^10 dense entries, more than max_mat_elements (2 x 10^9): the limit
  // used to refuse every sparse matrix above 44,721 DOFs. Its rows and columns count against max_matrix_dimension.
  const test::ScratchDir dir("mat-large-sparse");
  for (const mat_ft version : {MAT_FT_MAT5, MAT_FT_MAT4}) {
    const std::string path = dir.path(version == MAT_FT_MAT5 ? "v5.mat" : "v4.mat");
    {
      const MatPtr m(Mat_CreateVer(path.c_str(), nullptr, version));
      ASSERT_TRUE(m);
      std::vector<mat_uint32_t> jc(100001, 1);
      jc[0] = 0;
      jc[100000] = 2;
      PutSparse(m.get(), "K", 100000, 100000, {0, 99999}, jc, {3, 4}, MAT_COMPRESSION_NONE);
    }
    const SparseMatrix K = MatFile(path).sparse("K", "stiffness");
    EXPECT_EQ(K.rows(), 100000);
    EXPECT_EQ(K.coeff(0, 0), 3.0);
    EXPECT_EQ(K.coeff(99999, 99999), 4.0);
    ReaderLimits limits;
    limits.max_matrix_dimension = 50000;
    EXPECT_HAS(test::ErrorOf([&] { MatFile(path, limits).sparse("K", "stiffness"); }),
               "variable 'K': a sparse 100000 x 100000 matrix is larger than dynid reads (50000 rows or columns)");
  }
}

TEST(MatV5Reader, AgreesWithLibmatioOnRealFiles) {
  // The fuzz target's intact seeds (SciPy) and the real SMU / Georgia Tech files of ../shared/data (MATLAB).
  std::size_t compared = 0;
  for (const char* seed : {"model.mat", "modes.mat", "recording.mat"})
    compared += CompareWithLibmatio(test::CasesDir() + "/../fuzz/corpus/fuzz_mat/" + seed);
  EXPECT_EQ(compared, 4u + 4 + 2 + 4 + 128 + 1);  // K, M, frequency_hz, shapes, data, fs; cells of text not counted
  DYNID_REQUIRE_SHARED();
  std::size_t files = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(test::SharedDir() + "/data/real"))
    if (e.path().extension() == ".mat") {
      EXPECT_GT(CompareWithLibmatio(e.path().string()), 0u);
      ++files;
    }
  EXPECT_EQ(files, 4u);
}

// A file whose words are written in the other byte order: the 128-byte header marks it "MI", every 32-bit word
// and every double is byte-swapped; it must read as its little-endian twin.
std::string Words(bool big, std::initializer_list<std::uint32_t> words, const std::vector<double>& doubles = {}) {
  std::string f = "MATLAB 5.0 MAT-file, written by dynid's tests";
  f.resize(124, ' ');
  f += big ? std::string("\x01\x00MI", 4) : std::string("\x00\x01IM", 4);
  for (std::uint32_t w : words) {
    if (big) w = __builtin_bswap32(w);
    f.append(reinterpret_cast<const char*>(&w), 4);
  }
  for (double d : doubles) {
    std::uint64_t u;
    std::memcpy(&u, &d, 8);
    if (big) u = __builtin_bswap64(u);
    f.append(reinterpret_cast<const char*>(&u), 8);
  }
  return f;
}

TEST(MatV5Reader, BigEndianFilesReadAsTheirLittleEndianTwins) {
  const test::ScratchDir dir("mat-v5-endian");
  for (const bool big : {false, true}) {
    SCOPED_TRACE(big ? "big-endian" : "little-endian");
    // x = [1 2; 3 4] (double, 2 x 2; column-major 1 3 2 4), then c = {[5 6]} (a cell array of one 1 x 2 double).
    // A name in a small element is bytes, not a word: its letter goes first in either byte order.
    const auto name = [big](char letter) {
      return big ? static_cast<std::uint32_t>(letter) << 24 : static_cast<std::uint32_t>(letter);
    };
    const std::string path = WriteBytes(
        dir, big ? "big.mat" : "little.mat",
        Words(big, {14, 80, 6, 8, 6, 0, 5, 8, 2, 2, 0x00010001, name('x'), 9, 32}, {1, 3, 2, 4}) +
            Words(big,
                  {14, 112, 6, 8, 1, 0, 5, 8, 1, 1, 0x00010001, name('c'), 14, 64, 6, 8, 6, 0, 5, 8, 1, 2, 1, 0, 9, 16},
                  {5, 6})
                .substr(128));
    const MatFile f(path);
    ASSERT_EQ(f.variables().size(), 2u);
    const Eigen::MatrixXd x = f.matrix("x", "test");
    EXPECT_EQ(x(0, 1), 2.0);
    EXPECT_EQ(x(1, 0), 3.0);
    const std::vector<Eigen::MatrixXd> c = f.matrices("c", "test");
    ASSERT_EQ(c.size(), 1u);
    EXPECT_EQ(c[0](0, 1), 6.0);
  }
}

TEST(MatV5Reader, TextInEveryEncodingMatlabWrites) {
  // "ab" over "cd" (2 x 2, column-major a c b d) as miUINT16 (MATLAB's -v6/-v7), miUTF16 (17), miUTF32 (18) and
  // miUTF8 (16); non-ASCII characters read as '?' (dynid's labels are ASCII).
  const test::ScratchDir dir("mat-v5-text");
  const auto file = [&](std::uint32_t type, const std::string& data) {
    std::string bytes = Words(false, {14, static_cast<std::uint32_t>(48 + (data.size() + 7) / 8 * 8), 6, 8, 4, 0, 5, 8,
                                      2, 2, 0x00010001, 't', type, static_cast<std::uint32_t>(data.size())});
    bytes += data + std::string((8 - data.size() % 8) % 8, '\0');
    return MatFile(WriteBytes(dir, "t" + std::to_string(type) + ".mat", bytes)).strings("t", "labels");
  };
  const std::vector<std::string> want = {"ab", "cd"};
  EXPECT_EQ(file(4, std::string("a\0c\0b\0d\0", 8)), want);
  EXPECT_EQ(file(17, std::string("a\0c\0b\0d\0", 8)), want);
  EXPECT_EQ(file(18, std::string("a\0\0\0c\0\0\0b\0\0\0d\0\0\0", 16)), want);
  EXPECT_EQ(file(16, "acbd"), want);
  EXPECT_EQ(file(16,
                 "a\xc3\xa9"
                 "b\xe2\x86\x92"),
            (std::vector<std::string>{"ab", "??"}));  // a é b →
}

}  // namespace
}  // namespace dynid
