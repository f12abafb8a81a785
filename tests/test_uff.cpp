// UFF reader/writer and plain-text test-data readers: the shared sample files (values checked by hand and with
// pyuff's fixed-column logic), exact round trips, big-endian / single-precision binary, tolerance to Fortran
// quirks, and errors on corrupted or truncated files.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "dynid/io/test_data.hpp"
#include "dynid/io/uff.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

std::string UffDir() { return test::SharedDir() + "/data/uff-samples/"; }
std::string RealDir() { return test::SharedDir() + "/data/real/"; }

#define REQUIRE_DIR(dir)                                                                   \
  do {                                                                                     \
    if (!fs::is_directory(dir)) GTEST_SKIP() << "shared data folder " << (dir) << " not found"; \
  } while (0)

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A fresh temporary folder for files a test writes.
std::string TempFolder() {
  const fs::path p = fs::temp_directory_path() /
                     ("dynid_uff_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

/// The message of the InputError `f` throws ("" and a test failure if it throws none).
template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return "";
}

const Uff58& As58(const UffDataset& d) { return std::get<Uff58>(d.data); }

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectSame58(const Uff58& a, const Uff58& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.function_type, b.function_type);
  EXPECT_EQ(a.load_case, b.load_case);
  EXPECT_EQ(a.response_name, b.response_name);
  EXPECT_EQ(a.response_node, b.response_node);
  EXPECT_EQ(a.response_direction, b.response_direction);
  EXPECT_EQ(a.reference_name, b.reference_name);
  EXPECT_EQ(a.reference_node, b.reference_node);
  EXPECT_EQ(a.reference_direction, b.reference_direction);
  EXPECT_EQ(a.ordinate_type, b.ordinate_type);
  EXPECT_EQ(a.even, b.even);
  EXPECT_TRUE(SameBits(a.x_min, b.x_min));
  EXPECT_TRUE(SameBits(a.dx, b.dx));
  EXPECT_EQ(a.ordinate.data_type, b.ordinate.data_type);
  EXPECT_EQ(a.ordinate.unit, b.ordinate.unit);
  EXPECT_EQ(a.abscissa.label, b.abscissa.label);
  ASSERT_EQ(a.y.size(), b.y.size());
  for (Eigen::Index k = 0; k < a.y.size(); ++k) {
    ASSERT_TRUE(SameBits(a.x[k], b.x[k])) << "x at point " << k;
    ASSERT_TRUE(SameBits(a.y[k].real(), b.y[k].real()) && SameBits(a.y[k].imag(), b.y[k].imag())) << "point " << k;
  }
}

Uff58 Synthetic58(bool complex, bool even, int n) {
  Uff58 d;
  d.id[0] = "synthetic";
  d.function_type = complex ? 4 : 1;
  d.response_name = "acc 3";
  d.response_node = 3;
  d.response_direction = -2;
  d.reference_node = complex ? 7 : 0;
  d.reference_direction = complex ? 3 : 0;
  d.ordinate_type = complex ? 6 : 4;
  d.even = even;
  d.x_min = 0.125;
  d.dx = even ? 1.0 / 3.0 : 0.0;
  d.ordinate.data_type = 12;
  d.ordinate.unit = "m/s^2";
  d.abscissa.label = "Time";
  d.x.resize(n);
  d.y.resize(n);
  for (int k = 0; k < n; ++k) {
    d.x[k] = even ? d.x_min + static_cast<double>(k) * d.dx : 0.125 + std::sqrt(static_cast<double>(k)) * 1.1;
    d.y[k] = {std::sin(0.7 * k) * 1e-3 / 3.0, complex ? std::exp(-0.01 * k) / 7.0 : 0.0};
  }
  if (!even) d.dx = 0;
  return d;
}

// ---- the shared sample files --------------------------------------------------------------------------------------

/// Reads a sample and checks its dataset types and first lines.
UffFile ReadSample(const std::string& name, const std::vector<int>& types, const std::vector<int>& lines) {
  const UffFile f = read_uff(UffDir() + name);
  EXPECT_EQ(f.datasets.size(), types.size());
  for (std::size_t k = 0; k < std::min(types.size(), f.datasets.size()); ++k) {
    EXPECT_EQ(f.datasets[k].type, types[k]) << "dataset " << k;
    EXPECT_EQ(f.datasets[k].first_line, lines[k]) << "dataset " << k;
  }
  return f;
}

TEST(UffSamples, Ascii58TimeResponse) {
  REQUIRE_DIR(UffDir());
  const UffFile f = ReadSample("Sample_UFF58_ascii.uff", {58}, {1});
  ASSERT_EQ(f.datasets.size(), 1u);
  const Uff58& d = As58(f.datasets[0]);
  EXPECT_FALSE(d.binary);
  EXPECT_EQ(d.function_type, 1);
  EXPECT_EQ(d.ordinate_type, 2);
  EXPECT_EQ(d.id[0], "Mic 01.0Scalar");
  EXPECT_EQ(d.response_name, "Mic 01");
  EXPECT_EQ(d.num_points(), 79292);
  EXPECT_TRUE(d.even);
  EXPECT_EQ(d.dx, 1.52588e-05);
  EXPECT_EQ(d.ordinate.data_type, 21);
  EXPECT_EQ(d.ordinate.label, "Pressure");
  EXPECT_EQ(d.ordinate.unit, "Pa");
  EXPECT_EQ(d.abscissa.unit, "s");
  // First values on line 14 and the last on line 13229 (read by hand from the file).
  EXPECT_EQ(d.y[0].real(), -1.47553e-02);
  EXPECT_EQ(d.y[1].real(), -1.72957e-02);
  EXPECT_EQ(d.y[79291].real(), -4.31469e-03);
  EXPECT_EQ(d.y[79290].real(), 4.43632e-04);
}

TEST(UffSamples, Binary58SingleLittleEndian) {
  REQUIRE_DIR(UffDir());
  const UffFile f = ReadSample("Sample_UFF58b_bin.uff", {58}, {1});
  ASSERT_EQ(f.datasets.size(), 1u);
  const Uff58& d = As58(f.datasets[0]);
  EXPECT_TRUE(d.binary);
  EXPECT_FALSE(d.big_endian);
  EXPECT_EQ(d.ordinate_type, 2);
  ASSERT_EQ(d.num_points(), 79292);
  // float32 values decoded independently (Python struct '<f').
  EXPECT_EQ(d.y[0].real(), static_cast<double>(-0.014755260199308395f));
  EXPECT_EQ(d.y[79291].real(), static_cast<double>(-0.004314688965678215f));
  // The same record as the ASCII sample (which holds 6 significant digits).
  const UffFile a = read_uff(UffDir() + "Sample_UFF58_ascii.uff");
  EXPECT_LT((As58(a.datasets[0]).y - d.y).cwiseAbs().maxCoeff(), 5e-7);
}

TEST(UffSamples, Binary58DoubleAndRecording) {
  REQUIRE_DIR(UffDir());
  const UffFile f = ReadSample("binary8byte.uff", {58}, {1});
  ASSERT_EQ(f.datasets.size(), 1u);
  const Uff58& d = As58(f.datasets[0]);
  EXPECT_TRUE(d.binary);
  EXPECT_EQ(d.ordinate_type, 4);
  EXPECT_EQ(d.response_name, "sine 5 Hz");
  EXPECT_EQ(d.response_node, 1);
  EXPECT_EQ(d.num_points(), 250);
  EXPECT_EQ(d.dx, 0.01);
  EXPECT_EQ(d.y[1].real(), 0.30901697278022766);  // decoded with Python struct '<d'
  for (int k = 0; k < 250; ++k) EXPECT_NEAR(d.y[k].real(), std::sin(2 * M_PI * 5 * 0.01 * k), 1e-5) << k;  // stored from float32 samples
  const Recording r = uff_recording(f);
  EXPECT_EQ(r.num_channels(), 1);
  EXPECT_TRUE(test::RelClose(r.sample_rate_hz, 100.0, 1e-12));
  EXPECT_EQ(r.channels[0].quantity, Quantity::kAcceleration);
  EXPECT_EQ(r.channels[0].unit, "g");
  EXPECT_EQ(r.records[0].rows(), 250);
}

TEST(UffSamples, TestLabUnitsNodesAndSkipped) {
  REQUIRE_DIR(UffDir());
  const UffFile f = ReadSample("TestLab 161 164 18 15 82.uff", {151, 164, 18, 15, 82, 82, 82},
                                {1, 11, 17, 164, 203, 210, 219});
  ASSERT_EQ(f.datasets.size(), 7u);
  EXPECT_TRUE(std::holds_alternative<UffSkipped>(f.datasets[0].data));
  EXPECT_TRUE(std::holds_alternative<UffCoordinateSystems>(f.datasets[2].data));  // 18, read since issue 18
  EXPECT_TRUE(std::holds_alternative<UffSkipped>(f.datasets[4].data));
  const UffUnits& u = std::get<UffUnits>(f.datasets[1].data);
  EXPECT_EQ(u.code, 9);
  EXPECT_EQ(u.description, "USER_DEFINED");
  EXPECT_EQ(u.temperature_mode, 2);  // missing in the file: the default
  EXPECT_EQ(u.length, 1.0);
  EXPECT_EQ(u.temperature_offset, -2.73149999999999960e+02);  // written with a D exponent
  const UffNodes& n = std::get<UffNodes>(f.datasets[3].data);
  ASSERT_EQ(n.nodes.size(), 36u);
  EXPECT_EQ(n.nodes[6].id, 7);
  EXPECT_EQ(n.nodes[6].displacement_cs, 7);
  EXPECT_EQ(n.nodes[6].x, Eigen::Vector3d(-1.75, 0.0, 0.1));
  EXPECT_EQ(n.nodes[35].x, Eigen::Vector3d(1.2, 8.4, 0.0));
}

TEST(UffSamples, OrosNodesAndElements) {
  REQUIRE_DIR(UffDir());
  const UffFile f = ReadSample("mesh_Oros-modal_uff15_uff2412.uff", {18, 15, 2412}, {1, 8, 107});
  ASSERT_EQ(f.datasets.size(), 3u);
  const UffNodes& n = std::get<UffNodes>(f.datasets[1].data);
  ASSERT_EQ(n.nodes.size(), 96u);  // lines 10..105
  EXPECT_EQ(n.nodes[0].id, 7);
  EXPECT_EQ(n.nodes[0].x, Eigen::Vector3d(-51.619, 51.619, 50.0));
  const UffElements& e = std::get<UffElements>(f.datasets[2].data);
  ASSERT_EQ(e.elements.size(), 72u);  // lines 109..252, two per element
  EXPECT_EQ(e.elements[0].fe_descriptor, 44);
  EXPECT_EQ(e.elements[0].nodes, (std::vector<int>{1, 25, 48, 24}));
  EXPECT_EQ(e.elements[71].id, 72);
  EXPECT_EQ(e.elements[71].nodes, (std::vector<int>{50, 74, 73, 49}));
}

// ---- round trips --------------------------------------------------------------------------------------------------

TEST(UffRoundTrip, Dataset58AsciiAndBinaryExact) {
  for (const bool binary : {false, true})
    for (const bool complex : {false, true})
      for (const bool even : {true, false}) {
        SCOPED_TRACE(::testing::Message() << "binary " << binary << " complex " << complex << " even " << even);
        Uff58 d = Synthetic58(complex, even, 101);
        d.binary = binary;
        const UffFile f = parse_uff(format_uff58(d) + format_uff58(d), "memory");
        ASSERT_EQ(f.datasets.size(), 2u);
        ExpectSame58(d, As58(f.datasets[0]));
        EXPECT_EQ(As58(f.datasets[1]).binary, binary);
      }
}

TEST(UffRoundTrip, Dataset55_15_164Exact) {
  Uff55 m;
  m.values_per_node = 6;
  m.data_characteristic = 3;
  m.record7 = {2, 4, 1, 3};
  m.record8 = {12.345678901234567, 0.5, 0.0123456789, 0.0};
  m.nodes = {4, 9, 11};
  m.values = Eigen::MatrixXcd::Random(3, 6);
  m.values = m.values.real().cast<std::complex<double>>() / 3.0;
  UffNodes n;
  n.nodes = {{1, 0, 0, 8, {0.1, -2.0 / 3.0, 1e-17}}, {22, 1, 2, 3, {1e10 / 7.0, 0, -5.5}}};
  UffUnits u;
  u.code = 9;
  u.description = "USER";
  u.length = 0.001;
  u.temperature_offset = -273.15;
  const std::string text = format_uff164(u) + format_uff15(n) + format_uff55(m);
  const UffFile f = parse_uff(text, "memory");
  ASSERT_EQ(f.datasets.size(), 3u);
  const UffUnits& u2 = std::get<UffUnits>(f.datasets[0].data);
  EXPECT_EQ(u2.code, 9);
  EXPECT_EQ(u2.description, "USER");
  EXPECT_TRUE(SameBits(u2.length, 0.001));
  EXPECT_TRUE(SameBits(u2.temperature_offset, -273.15));
  const UffNodes& n2 = std::get<UffNodes>(f.datasets[1].data);
  ASSERT_EQ(n2.nodes.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(n2.nodes[k].id, n.nodes[k].id);
    EXPECT_EQ(n2.nodes[k].colour, n.nodes[k].colour);
    for (int j = 0; j < 3; ++j) EXPECT_TRUE(SameBits(n2.nodes[k].x[j], n.nodes[k].x[j]));
  }
  const Uff55& m2 = std::get<Uff55>(f.datasets[2].data);
  EXPECT_EQ(m2.nodes, m.nodes);
  EXPECT_EQ(m2.mode_number(), 3);
  EXPECT_TRUE(SameBits(m2.frequency_hz(), 12.345678901234567));
  EXPECT_TRUE(SameBits(m2.damping_ratio(), 0.0123456789));
  EXPECT_TRUE(m2.values == m.values);
  // Writing what was read gives the same text.
  EXPECT_EQ(format_uff164(u2) + format_uff15(n2) + format_uff55(m2), text);
}

TEST(UffRoundTrip, RecordingFrfAndModalDataFiles) {
  const std::string dir = TempFolder();
  Recording r;
  r.sample_rate_hz = 1024;
  r.source = "synthetic";
  r.channels = {{"hammer", {1, Dof::UZ}, Quantity::kForce, "N", true},
                {"acc 2", {2, Dof::UZ}, Quantity::kAcceleration, "m/s^2", false},
                {"rot", {2, Dof::RX}, Quantity::kVelocity, "rad/s", false}};
  r.records = {Eigen::MatrixXd::Random(300, 3), Eigen::MatrixXd::Random(300, 3) / 7.0};
  for (const bool binary : {false, true}) {
    const std::string p = dir + (binary ? "/rec-bin.uff" : "/rec.uff");
    write_uff58_recording(p, r, binary, false);
    const Recording q = uff_recording(read_uff(p));
    ASSERT_EQ(q.num_channels(), 3);
    ASSERT_EQ(q.records.size(), 2u);
    EXPECT_TRUE(q.records[0] == r.records[0] && q.records[1] == r.records[1]) << "samples differ";
    EXPECT_EQ(q.sample_rate_hz, 1024.0);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(q.channels[c].name, r.channels[c].name);
      EXPECT_TRUE(q.channels[c].dof == r.channels[c].dof);
      EXPECT_EQ(q.channels[c].quantity, r.channels[c].quantity);
      EXPECT_EQ(q.channels[c].unit, r.channels[c].unit);
      EXPECT_EQ(q.channels[c].input, r.channels[c].input);
    }
  }
  EXPECT_NE(ErrorOf([&] { write_uff58_recording(dir + "/rec.uff", r, false, false); }).find("file exists"),
            std::string::npos);

  FrfData h;
  h.frequency_hz = Eigen::VectorXd::LinSpaced(64, 0.0, 63.0 * 0.25);
  h.outputs = {{"a1", {1, Dof::UX}, Quantity::kAcceleration, "g", false}, {"a2", {5, Dof::UY}, Quantity::kAcceleration, "g", false}};
  h.inputs = {{"f1", {1, Dof::UX}, Quantity::kForce, "N", true}, {"f3", {3, Dof::UZ}, Quantity::kForce, "N", true}};
  h.H = Eigen::MatrixXcd::Random(64, 4);
  h.coherence = Eigen::MatrixXd::Random(64, 4).cwiseAbs();  // one per output/input pair (ordinary coherence, type 6)
  for (const bool binary : {false, true}) {
    const std::string p = dir + (binary ? "/frf-bin.uff" : "/frf.uff");
    write_uff58_frf(p, h, binary, false);
    const UffFile f = read_uff(p);
    EXPECT_TRUE(As58(f.datasets[0]).even);
    const FrfData g = uff_frf(f);
    EXPECT_TRUE(g.frequency_hz == h.frequency_hz);
    EXPECT_TRUE(g.H == h.H);
    EXPECT_TRUE(g.coherence == h.coherence);
    ASSERT_EQ(g.num_outputs(), 2);
    ASSERT_EQ(g.num_inputs(), 2);
    EXPECT_TRUE(g.inputs[1].dof == h.inputs[1].dof);
    EXPECT_EQ(g.outputs[1].name, "a2");
  }
  // A missing output/input pair is named.
  std::vector<UffDataset> ds = uff_datasets(h, false);
  ds.erase(ds.begin() + 1);  // output 5uy over input 1ux
  write_uff(dir + "/frf-missing.uff", ds, false);
  const std::string e = ErrorOf([&] { uff_frf(read_uff(dir + "/frf-missing.uff")); });
  EXPECT_NE(e.find("missing FRFs for output/input pairs 5uy/1ux"), std::string::npos) << e;

  ModalData m;
  m.dofs = {{2, Dof::UX}, {2, Dof::UZ}, {4, Dof::UY}, {4, Dof::RZ}};
  m.frequencies_hz = Eigen::Vector3d(1.5, 7.25 / 3.0, 40.0 / 7.0);
  m.shapes = Eigen::MatrixXd::Random(4, 3);
  m.damping_ratios = Eigen::Vector3d(0.01, 0.02 / 3.0, 0.0);
  write_uff55(dir + "/modes.uff", m, false);
  const ModalData m2 = uff_modal_data(read_uff(dir + "/modes.uff"));
  ASSERT_EQ(m2.dofs.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_TRUE(m2.dofs[k] == m.dofs[k]);
  EXPECT_TRUE(m2.frequencies_hz == m.frequencies_hz);
  EXPECT_TRUE(m2.shapes == m.shapes);
  EXPECT_TRUE(m2.damping_ratios == m.damping_ratios);
  fs::remove_all(dir);
}

// ---- binary variants written by hand ------------------------------------------------------------------------------

std::string Binary58Header(int byte_order, int type, int n, int bytes) {
  char line[200];
  std::string s = "    -1\n";
  std::snprintf(line, sizeof line, "%6db%6d%6d%12d%12d%6d%6d%12d%12d\n", 58, byte_order, 2, 11, bytes, 0, 0, 0, 0);
  s += line;
  s += "id1\nNONE\nNONE\nNONE\nNONE\n";
  s += "    1         0    0         0 NONE               2   3 NONE               0   0\n";
  std::snprintf(line, sizeof line, "%10d%10d%10d%13.5e%13.5e%13.5e\n", type, n, 1, 0.0, 0.5, 0.0);
  s += line;
  s += "        17    0    0    0 Time                 s                   \n";
  s += "        12    0    0    0 Acceleration         g                   \n";
  s += "         0    0    0    0 NONE                 NONE                \n";
  s += "         0    0    0    0 NONE                 NONE                \n";
  return s;
}

TEST(UffBinary, BigEndianFloat32AndLittleEndianComplexSingle) {
  const float v[5] = {1.5f, -2.25f, 3.0e-7f, 1e20f, -0.1f};
  std::string s = Binary58Header(2, 2, 5, 20);
  for (float x : v) {
    std::uint32_t u;
    std::memcpy(&u, &x, 4);
    for (int k = 3; k >= 0; --k) s.push_back(static_cast<char>((u >> (8 * k)) & 0xFF));  // big endian
  }
  s += "    -1\n";
  const UffFile f = parse_uff(s, "big-endian.uff");
  const Uff58& d = As58(f.datasets[0]);
  EXPECT_TRUE(d.big_endian);
  ASSERT_EQ(d.num_points(), 5);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(d.y[k].real(), static_cast<double>(v[k]));
  EXPECT_EQ(d.x[4], 2.0);
  EXPECT_EQ(d.response_direction, 3);

  std::string c = Binary58Header(1, 5, 2, 16);
  for (float x : {1.0f, -1.0f, 0.25f, 8.0f}) c.append(reinterpret_cast<const char*>(&x), 4);  // host order = little
  c += "    -1\n";
  const UffFile fc = parse_uff(c, "complex.uff");
  const Uff58& e = As58(fc.datasets[0]);
  EXPECT_EQ(e.y[0], std::complex<double>(1.0, -1.0));
  EXPECT_EQ(e.y[1], std::complex<double>(0.25, 8.0));
}

// ---- Fortran quirks -----------------------------------------------------------------------------------------------

TEST(UffTolerance, RunTogetherFieldsDExponentsCrlfAndBlanks) {
  std::string s =
      "\r\n    -1   \r\n    58\r\nname\r\n\r\n\r\n\r\n\r\n"
      "    4         0    0         0 NONE              12  -1 NONE              20   2\r\n"
      "         5         5         1  0.00000D+00  2.50000D-01\r\n"  // z value missing, D exponents
      "        18    0    0    0 Frequency            Hz\r\n"
      "        12    0    0    0 Acceleration         g\r\n"
      "        13    0    0    0 Force                N\r\n"
      "         0    0    0    0\r\n"
      "-1.23456E+00-2.34567E+00 3.45678E+00-4.56789E-01-5.67891E+01-6.78912E-02   \r\n"
      " 7.00000D+00-8.00000E+00-9.12345E+00 1.00000E+01\r\n"
      "    -1    \r\n\r\n";
  const UffFile f = parse_uff(s, "quirks.uff");
  ASSERT_EQ(f.datasets.size(), 1u);
  EXPECT_EQ(f.datasets[0].first_line, 2);
  const Uff58& d = As58(f.datasets[0]);
  EXPECT_EQ(d.response_node, 12);
  EXPECT_EQ(d.response_direction, -1);
  EXPECT_EQ(d.reference_node, 20);
  EXPECT_EQ(d.dx, 0.25);
  EXPECT_EQ(d.z_value, 0.0);
  EXPECT_EQ(d.ordinate.unit, "g");
  ASSERT_EQ(d.num_points(), 5);
  EXPECT_EQ(d.y[0], std::complex<double>(-1.23456, -2.34567));
  EXPECT_EQ(d.y[2], std::complex<double>(-56.7891, -6.78912e-2));
  EXPECT_EQ(d.y[3], std::complex<double>(7.0, -8.0));
  EXPECT_EQ(d.y[4], std::complex<double>(-9.12345, 10.0));
  // The FRF: response direction -1 flips the sign, so the output is 12ux.
  const FrfData h = uff_frf(f);
  EXPECT_TRUE(h.outputs[0].dof == (MeasuredDof{12, Dof::UX}));
  EXPECT_TRUE(h.inputs[0].dof == (MeasuredDof{20, Dof::UY}));
  EXPECT_EQ(h(0, 0, 0), std::complex<double>(1.23456, 2.34567));

  const std::string nodes =
      "    -1\n    15\n         1         0         0         1-1.23456E+00-2.34567E+00 3.00000D+00\n"
      "         2         0         0         1-1.23456E+100-2.34567E-100  3.00000D+00\n    -1\n";
  const UffFile fn = parse_uff(nodes, "nodes.uff");
  const UffNodes& n = std::get<UffNodes>(fn.datasets[0].data);
  EXPECT_EQ(n.nodes[0].x, Eigen::Vector3d(-1.23456, -2.34567, 3.0));
  EXPECT_EQ(n.nodes[1].x, Eigen::Vector3d(-1.23456e100, -2.34567e-100, 3.0));  // E13.5 with 3-digit exponents
}

// ---- errors -------------------------------------------------------------------------------------------------------

TEST(UffErrors, TruncatedAndGarbledSamples) {
  REQUIRE_DIR(UffDir());
  const std::string ascii = Slurp(UffDir() + "Sample_UFF58_ascii.uff");
  std::string e = ErrorOf([&] { parse_uff(ascii.substr(0, ascii.size() / 2), "half.uff"); });
  EXPECT_NE(e.find("half.uff: dataset 58 starting at line 1, record 12"), std::string::npos) << e;
  EXPECT_NE(e.find("of the 79292 values declared"), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;

  const std::string bin = Slurp(UffDir() + "Sample_UFF58b_bin.uff");
  e = ErrorOf([&] { parse_uff(bin.substr(0, bin.size() / 2), "half-bin.uff"); });
  EXPECT_NE(e.find("dataset 58b starting at line 1, record 12"), std::string::npos) << e;
  EXPECT_NE(e.find("317168 bytes needed"), std::string::npos) << e;

  // No closing -1.
  std::string open = ascii.substr(0, ascii.rfind("-1"));
  e = ErrorOf([&] { parse_uff(open, "open.uff"); });
  EXPECT_NE(e.find("closing -1"), std::string::npos) << e;

  // A garbled header field: ordinate data type 7, then a non-numeric number of points.
  std::string bad = ascii;
  bad.replace(bad.find("         2     79292"), 20, "         7     79292");
  e = ErrorOf([&] { parse_uff(bad, "bad.uff"); });
  EXPECT_NE(e.find("bad.uff: dataset 58 starting at line 1, record 7 (line 9): ordinate data type"), std::string::npos) << e;
  bad = ascii;
  bad.replace(bad.find("         2     79292"), 20, "         2     7x292");
  e = ErrorOf([&] { parse_uff(bad, "bad.uff"); });
  EXPECT_NE(e.find("record 7 (line 9)"), std::string::npos) << e;

  // A non-number in the data names the line.
  bad = ascii;
  bad.replace(bad.find("-1.53846E-02"), 12, "-1.5384#E-02");
  e = ErrorOf([&] { parse_uff(bad, "bad.uff"); });
  EXPECT_NE(e.find("record 12 (line 23)"), std::string::npos) << e;

  EXPECT_NE(ErrorOf([&] { parse_uff("hello\n", "text.uff"); }).find("text.uff: line 1: expected the -1 line"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { read_uff("/nonexistent/x.uff"); }).find("cannot open"), std::string::npos);
  // A 55 whose last node lacks values.
  const std::string m55 = "    -1\n    55\nA\nB\nC\nD\nE\n         1         2         2         8         2         3\n"
                          "         2         4         1         1\n  1.0  0.0  0.01  0.0\n         1\n 1.0 2.0 3.0\n"
                          "         2\n 1.0\n    -1\n";
  e = ErrorOf([&] { parse_uff(m55, "m.uff"); });
  EXPECT_NE(e.find("m.uff: dataset 55 starting at line 1, record 10 (line 13): node 2: expected 3 values, found 1"),
            std::string::npos) << e;
}

// ---- plain-text readers -------------------------------------------------------------------------------------------

TEST(TextData, FrfTextFiles) {
  REQUIRE_DIR(RealDir());
  const std::string dir = RealDir() + "tool-impact-test/";
  const TextTable t = read_text_table(dir + "frf_point_1.txt");
  EXPECT_EQ(t.x.size(), 5001);  // wc -l
  EXPECT_EQ(t.dx, 1.0);
  std::vector<std::string> paths;
  std::vector<MeasuredDof> outputs, inputs;
  for (int n = 1; n <= 5; ++n) {
    paths.push_back(dir + "frf_point_" + std::to_string(n) + ".txt");
    outputs.push_back({1, Dof::UY});
    inputs.push_back({n, Dof::UY});
  }
  const FrfData h = read_frf_text_set(paths, outputs, inputs);
  EXPECT_EQ(h.num_outputs(), 1);
  EXPECT_EQ(h.num_inputs(), 5);
  EXPECT_EQ(h(0, 0, 0), std::complex<double>(7.735887e-001, 0.0));
  EXPECT_EQ(h(1, 0, 0), std::complex<double>(1.193506e-002, -1.217864e-003));
  EXPECT_EQ(h.frequency_hz[5000], 5000.0);
  const std::string e = ErrorOf([&] {
    read_frf_text_set({paths[0], paths[1]}, {{1, Dof::UY}, {2, Dof::UY}}, {{1, Dof::UY}, {2, Dof::UY}});
  });
  EXPECT_NE(e.find("missing FRFs for output/input pairs 2uy/1uy, 1uy/2uy"), std::string::npos) << e;
}

TEST(TextData, ImpactTimeHistory) {
  REQUIRE_DIR(RealDir());
  const Recording r = read_time_text(RealDir() + "tool-impact-test/impact_point1_time.txt");
  EXPECT_TRUE(test::RelClose(r.sample_rate_hz, 51200.0, 1e-6));
  EXPECT_EQ(r.num_channels(), 2);
  EXPECT_EQ(r.records[0].rows(), 51200);
  EXPECT_EQ(r.records[0](1, 1), 3.131658e-001);
}

TEST(TextData, LabViewFiles) {
  REQUIRE_DIR(RealDir());
  const std::string dir = RealDir() + "usc-cantilever-ds4/";
  const LvmFile fft = read_lvm(dir + "FFT_data.lvm");
  EXPECT_TRUE(fft.spectrum);
  EXPECT_EQ(fft.table.x.size(), 150000);
  EXPECT_NEAR(fft.table.dx, 12800.0 / 150000.0, 1e-6);  // 0.0853333 Hz
  EXPECT_EQ(fft.header_delta_x, 0.085333);
  ASSERT_EQ(fft.table.names.size(), 1u);
  EXPECT_EQ(fft.table.names[0], "Acceleration (FFT - (RMS))");
  EXPECT_EQ(fft.table.columns(0, 0), -76.981792);

  const TestData d = read_test_data(dir + "data_set_1_downsampled_by_16.lvm");
  ASSERT_EQ(d.kind, TestData::Kind::kTimeHistory);
  const Recording& r = d.recording;
  EXPECT_TRUE(test::RelClose(r.sample_rate_hz, 3200.0, 1e-6));
  EXPECT_EQ(r.records[0].rows(), 63041);
  ASSERT_EQ(r.num_channels(), 3);
  EXPECT_EQ(r.channels[1].name, "Force");
  EXPECT_EQ(r.channels[1].unit, "Pounds");
  EXPECT_TRUE(r.channels[1].input);
  EXPECT_EQ(r.channels[2].quantity, Quantity::kAcceleration);
}

TEST(TextData, CsvWithHeaderCommentsAndErrors) {
  const std::string dir = TempFolder();
  std::ofstream(dir + "/ok.csv") << "# a comment\ntime,force,acc\n0,1,2\n0.001,3,4\n\n0.002,5,6\n";
  const Recording r = read_time_text(dir + "/ok.csv");
  EXPECT_TRUE(test::RelClose(r.sample_rate_hz, 1000.0, 1e-12));
  EXPECT_EQ(r.channels[0].name, "force");
  EXPECT_TRUE(r.channels[0].input);
  EXPECT_EQ(r.records[0](2, 1), 6.0);
  const Recording q = read_time_text(dir + "/ok.csv", 200.0);  // no time column: 3 channels
  EXPECT_EQ(q.num_channels(), 3);

  std::ofstream(dir + "/uneven.txt") << "0 1\n0.1 2\n0.2 3\n0.35 4\n0.45 5\n";
  std::string e = ErrorOf([&] { read_time_text(dir + "/uneven.txt"); });
  EXPECT_NE(e.find("uneven.txt:4: the step changes"), std::string::npos) << e;
  std::ofstream(dir + "/cell.csv") << "t,a\n0,1\n1,x2\n";
  e = ErrorOf([&] { read_time_text(dir + "/cell.csv"); });
  EXPECT_NE(e.find("cell.csv:3: column 2: 'x2' is not a number"), std::string::npos) << e;
  std::ofstream(dir + "/short.csv") << "0 1 2\n1 2\n";
  e = ErrorOf([&] { read_time_text(dir + "/short.csv"); });
  EXPECT_NE(e.find("short.csv:2: 2 fields"), std::string::npos) << e;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dynid
