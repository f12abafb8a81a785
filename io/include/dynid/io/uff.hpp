// dynid/io/uff.hpp -- Universal File Format (UFF / UNV) reader and writer for test data.
//
// A UFF file is a sequence of datasets, each framed by lines holding only "-1":
//       -1
//       58            <- dataset type (I6); "58b" marks a binary 58 (see below)
//   ... records ...
//       -1
// Records are Fortran fixed-format lines. dynid reads each numeric record by whitespace first and, when that
// fails (fields run together, e.g. "-1.23456E+100-2.34567E+100"), by the fixed column widths of the record's
// format, as pyuff does, and failing that by cutting before each sign that follows a digit (writers that use
// narrower fields than the format, e.g. "-1.23456E+00-2.34567E+00"). Fortran "D" exponents, CRLF line ends, trailing blanks, blank lines between datasets
// and missing trailing optional fields are accepted.
//
// Datasets understood:
//   58   function at a nodal DOF (time response, FRF, spectra, coherence...):
//          records 1-5  ID lines (80A1; record 1 is usually the function's name)
//          record 6     I5,I10,I5,I10,1X,A10,I10,I4,1X,A10,I10,I4: function type (1 time response, 2 auto
//                       spectrum, 3 cross spectrum, 4 FRF, 5 transmissibility, 6 coherence, 9 PSD, 26 multiple
//                       coherence ...), function id, version, load case, response entity name, response node,
//                       response direction, reference entity name, reference node, reference direction.
//                       Directions: 0 scalar, 1..6 = X, Y, Z, RX, RY, RZ, negative = opposite sense.
//          record 7     3I10,3E13.5: ordinate data type (2 real single, 4 real double, 5 complex single,
//                       6 complex double), number of points, abscissa spacing (1 even, 0 uneven), abscissa
//                       minimum, increment, z-axis value.
//          records 8-11 I10,3I5,2(1X,A20): specific data type, length/force/temperature unit exponents, axis label
//                       and units label of the abscissa, ordinate (numerator), ordinate denominator, z axis.
//                       Specific data types: 0 unknown, 1 general, 2 stress, 3 strain, 5 temperature,
//                       6 heat flux, 8 displacement, 9 reaction force, 11 velocity, 12 acceleration,
//                       13 excitation force, 15 pressure, 16 mass, 17 time, 18 frequency, 19 rpm, 20 order,
//                       21 sound pressure.
//          record 12    the values: even spacing y (real) or re, im (complex) per point; uneven spacing
//                       x, y or x, re, im per point. ASCII formats: 6E13.5 (single), 4E20.12 (double even),
//                       2(E13.5,E20.12) (double real uneven), E13.5,2E20.12 (double complex uneven).
//   58b  the same with record 12 in binary. Its type line is
//          "58b  byte_order  fp_format  num_ascii_lines  num_bytes  0  0  0  0" (I6,1A1,I6,I6,I12,I12,I6,I6,I12,I12):
//          byte order 1 little endian, 2 big endian; fp format 2 IEEE 754; 11 ASCII lines (records 1-11) follow,
//          then the values as 4-byte (types 2, 5) or 8-byte (4, 6) floats, directly followed by the "-1" line.
//   55   data at nodes (modes): record 6 model type, analysis type (2 normal modes, 3 complex modes, 5 frequency
//        response, 7 complex modes 2nd order), data characteristic (2 three DOFs, 3 six DOFs), specific data
//        type, data type (2 real, 5 complex), values per node (3 or 6); record 7 integers (load case, mode
//        number); record 8 reals (normal modes: frequency, modal mass, viscous and hysteretic damping ratio;
//        complex: eigenvalue re/im [rad/s], modal A re/im, modal B re/im); then per node a line with the node
//        number and the node's values (6E13.5, continued on further lines).
//   15   nodes: 4I10,3E13.5 per node (label, definition and displacement coordinate systems, colour, x, y, z).
//   2411 nodes, double precision: 4I10 then 3D25.16 per node.
//   2412 elements: 6I10 (label, FE descriptor, physical and material property, colour, number of nodes),
//        for beams (descriptors 11, 21-24) a line of orientation/cross-section ids, then the nodes (8I10 per line).
//        The connectivity is kept as it is.
//   164  units: I10,20A1,I10 (code, description, temperature mode), 3D25.17 (length, force, temperature
//        factors), D25.17 (temperature offset).
//   2414 analysis data (FE results: the mode shapes NX, Simcenter, I-DEAS and Permas export): record 1 label (I10),
//        2 name (40A2), 3 dataset location (I10: 1 data at nodes, 2 on elements, 3 at nodes on elements, 5 at
//        points), 4-8 ID lines, 9 (6I10) model type, analysis type (1 static, 2 normal mode, 3 complex
//        eigenvalue first order, 4 transient, 5 frequency response, 6 buckling, 7 complex eigenvalue second
//        order), data characteristic (1 scalar, 2 three-DOF vector, 3 six-DOF vector, 4 symmetric tensor),
//        result type (8 displacement, 11 velocity, 12 acceleration, ...), data type (1 integer, 2 single,
//        4 double, 5 single complex, 6 double complex), values per node (NVALDC); 10-11 (8I10, 2I10) integers:
//        design set, iteration, solution set, boundary condition, load set, mode number, time step, frequency
//        number, creation option, number retained; 12-13 (6E13.5 each) reals: time, frequency [Hz], eigenvalue,
//        modal mass, viscous damping ratio, hysteretic damping ratio, eigenvalue re/im, modal A re/im, modal B
//        re/im; then for data at nodes, per node record 14 (node, I10) and record 15 (its NVALDC values, real or
//        re/im pairs, on as many lines as they take). Other locations are kept without values (a note says so).
//   18   coordinate systems: per system record 1 (5I10: number, type 0 Cartesian / 1 cylindrical / 2 spherical,
//        reference system, colour, method of definition 1), record 2 name (20A2), record 3 (6E13.5: origin and a
//        point on the +x axis) and record 4 (3E13.5: a point in the +xz plane), all in the reference system.
//   2420 coordinate systems: record 1 part UID, record 2 part name, then per system record 3 (3I10: label, type,
//        colour), record 4 name, records 5-8 (3D25.16 each): rows 1-3 the local x, y, z axes as unit vectors in
//        global coordinates, row 4 the origin.
// Coordinate systems are applied after reading: points of 15/2411 defined in a local system (definition
// coordinate system != 0) are converted to global coordinates (cylindrical: r, theta [deg] about local z, z;
// spherical: r, theta [deg] from local z, phi [deg] about local z from local x), and the nodal vectors of 55
// and 2414 at nodes whose displacement coordinate system is local are turned into global directions (the
// system's axes at the node: radial, tangential, axial for cylindrical systems). A point or vector whose
// system the file does not define keeps its values, and a note says so (UffNode::global is false).
// Other datasets (151, 82, ...) are skipped; they are listed with their type and line.
//
// Writing: dynid writes 58 in ASCII (values with 17 significant digits, 3 per line, so doubles read back exactly;
// this is wider than the standard E20.12, so only readers that split on blanks read it) or binary 58b (little
// endian, 8-byte floats; exact and readable by any UFF reader). 55 (real modes), 15 and 164 are written likewise
// with 17 significant digits.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <variant>
#include <vector>

#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/recording.hpp"

namespace dynid {

/// Characteristics of one axis of a 58 dataset (records 8-11).
struct UffAxis {
  int data_type = 0;           ///< specific data type (17 time, 18 frequency, 12 acceleration, 13 excitation force...)
  int length_exp = 0, force_exp = 0, temperature_exp = 0;
  std::string label = "NONE";  ///< axis label (20 characters)
  std::string unit = "NONE";   ///< units label (20 characters)
};

/// Dataset 58 / 58b: one function at a nodal DOF.
struct Uff58 {
  std::array<std::string, 5> id{{"NONE", "NONE", "NONE", "NONE", "NONE"}};
  int function_type = 1;       ///< 1 time response, 4 FRF, 2 auto spectrum, 3 cross spectrum, 6 coherence...
  int function_id = 0, version = 0, load_case = 0;
  std::string response_name = "NONE";
  int response_node = 0, response_direction = 0;
  std::string reference_name = "NONE";
  int reference_node = 0, reference_direction = 0;
  int ordinate_type = 4;       ///< 2 real single, 4 real double, 5 complex single, 6 complex double
  bool even = true;            ///< abscissa spacing
  double x_min = 0, dx = 0, z_value = 0;
  UffAxis abscissa, ordinate, denominator, z_axis;
  Eigen::VectorXd x;           ///< abscissa of every point (computed from x_min + k dx when even)
  Eigen::VectorXcd y;          ///< ordinate (imaginary part 0 for real data)
  // How it was stored (read) or is to be stored (written):
  bool binary = false;
  bool big_endian = false;

  bool is_complex() const { return ordinate_type == 5 || ordinate_type == 6; }
  bool is_double() const { return ordinate_type == 4 || ordinate_type == 6; }
  int num_points() const { return static_cast<int>(y.size()); }
};

/// Dataset 55: data at nodes (one mode, or one frequency of a frequency response).
struct Uff55 {
  std::array<std::string, 5> id{{"NONE", "NONE", "NONE", "NONE", "NONE"}};
  int model_type = 1, analysis_type = 2, data_characteristic = 2, data_type_code = 8;  ///< record 6 fields 1-4
  bool complex = false;        ///< record 6 field 5: 5 complex, 2 real
  int values_per_node = 3;     ///< 3 or 6
  std::vector<int> record7{2, 4, 1, 1};     ///< integers of record 7 (n ints, n reals, load case, mode number)
  std::vector<double> record8{0, 0, 0, 0};  ///< reals of record 8 (see the header comment)
  std::vector<int> nodes;
  Eigen::MatrixXcd values;     ///< nodes x values_per_node

  int mode_number() const { return record7.size() > 3 ? record7[3] : 0; }
  bool in_global = true;       ///< vectors are in global directions (see the header comment)
  /// Natural frequency [Hz]: record 8 field 1 for normal modes and frequency response, |eigenvalue| / 2 pi for
  /// complex modes.
  double frequency_hz() const;
  /// Damping ratio: viscous damping ratio (record 8 field 3) for normal modes, -Re(eigenvalue)/|eigenvalue| for
  /// complex modes, else 0.
  double damping_ratio() const;
};

/// Dataset 2414: analysis data (FE results). Data at nodes (location 1) are kept; other locations only their
/// header.
struct Uff2414 {
  int label = 1;
  std::string name = "NONE";
  int location = 1;            ///< 1 data at nodes, 2 on elements, 3 at nodes on elements, 5 at points
  std::array<std::string, 5> id{{"NONE", "NONE", "NONE", "NONE", "NONE"}};
  int model_type = 1, analysis_type = 2, data_characteristic = 2, result_type = 8, data_type = 2;
  int values_per_node = 3;     ///< NVALDC
  std::vector<int> integers = std::vector<int>(10, 0);    ///< records 10-11
  std::vector<double> reals = std::vector<double>(12, 0.0);  ///< records 12-13
  std::vector<int> nodes;
  Eigen::MatrixXcd values;     ///< nodes x values_per_node (data at nodes)
  bool in_global = true;       ///< vectors are in global directions (see the header comment)

  bool complex() const { return data_type == 5 || data_type == 6; }
  int mode_number() const { return integers.size() > 5 ? integers[5] : 0; }
  /// Hz: record 12 field 2 for normal modes and frequency response; |eigenvalue| / 2 pi (record 13 fields 1-2)
  /// for complex modes.
  double frequency_hz() const;
  /// Viscous damping ratio (record 12 field 5) of normal modes; -Re(eigenvalue)/|eigenvalue| of complex modes.
  double damping_ratio() const;
};

/// Datasets 18 and 2420: coordinate systems, resolved to global axes and origin after reading.
struct UffCoordinateSystem {
  int id = 0;
  int type = 0;                ///< 0 Cartesian, 1 cylindrical, 2 spherical
  int reference = 0;           ///< 18: the system the definition points are given in
  std::string name;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< columns: local x, y, z unit vectors (global)
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();    ///< global
  std::array<Eigen::Vector3d, 3> definition{};         ///< 18: origin, +x point, +xz point (reference system)
  bool resolved = false;       ///< axes and origin are known in global coordinates
  /// Global coordinates of a point given in this system (r, theta, z / r, theta, phi for curvilinear ones).
  Eigen::Vector3d to_global(const Eigen::Vector3d& p) const;
  /// The system's unit directions at a point (global coordinates), as columns: x, y, z for Cartesian systems;
  /// radial, tangential, axial for cylindrical; radial, theta, phi for spherical.
  Eigen::Matrix3d directions_at(const Eigen::Vector3d& global_point) const;
};
struct UffCoordinateSystems {
  int part_uid = 0;            ///< 2420
  std::string part_name;       ///< 2420
  std::vector<UffCoordinateSystem> systems;
};

/// Dataset 15 or 2411: nodes.
struct UffNode {
  int id = 0, definition_cs = 0, displacement_cs = 0, colour = 0;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  ///< global coordinates (converted from the definition system)
  Eigen::Vector3d x_file = Eigen::Vector3d::Zero();  ///< the coordinates as written, in the definition system
  bool global = true;  ///< false: the definition system is not in the file; x holds the coordinates as written
};
struct UffNodes {
  std::vector<UffNode> nodes;
};

/// Dataset 2412: elements (connectivity kept as it is, any element type).
struct UffElement {
  int id = 0, fe_descriptor = 0, physical_property = 0, material_property = 0, colour = 0;
  std::vector<int> nodes;
};
struct UffElements {
  std::vector<UffElement> elements;
};

/// Dataset 164: units.
struct UffUnits {
  int code = 1;                ///< 1 SI (m, kg, s), 2 BG, ... 9 user defined
  std::string description = "SI";
  int temperature_mode = 2;    ///< 1 absolute, 2 relative
  double length = 1, force = 1, temperature = 1, temperature_offset = 273.15;  ///< factors to SI
};

/// Any other dataset: its type is listed, its content ignored.
struct UffSkipped {};

struct UffDataset {
  int type = 0;                ///< 58 (also for 58b), 55, 15, 2411, 2412, 164, 2414, 18, 2420, or the skipped type
  int first_line = 0;          ///< line of the opening "-1" (1-based)
  std::variant<UffSkipped, Uff58, Uff55, UffNodes, UffElements, UffUnits, Uff2414, UffCoordinateSystems> data;
};

struct UffFile {
  std::string source;          ///< the file read
  std::vector<UffDataset> datasets;
  std::vector<std::string> notes;  ///< what was tolerated or kept as is (e.g. higher-order elements)
};

/// Reads a UFF file. Throws InputError naming the file, the dataset, its first line, the record and the field.
UffFile read_uff(const std::string& path);
/// Parses UFF bytes; `name` is used in messages.
UffFile parse_uff(const std::string& bytes, const std::string& name);

/// The text of one dataset, ready to concatenate into a file (writers for 58/58b, 55, 15, 164).
std::string format_uff58(const Uff58& d);  ///< binary 58b when d.binary (always little endian, 8-byte floats)
std::string format_uff55(const Uff55& d);  ///< real or complex values
std::string format_uff15(const UffNodes& d);
std::string format_uff164(const UffUnits& d);
/// Writes the datasets (58, 55, 15 and 164 supported; others throw InputError) with write_file_atomic.
void write_uff(const std::string& path, const std::vector<UffDataset>& datasets, bool overwrite);

/// Name of a 58 function type ("time response", "FRF", ...) and of a specific data type ("acceleration"...).
std::string uff_function_type_name(int type);
std::string uff_data_type_name(int type);

// ---- Conversions to and from dynid's test data -----------------------------------------------------------------

/// The channel a 58 dataset measures: its response DOF (node, direction; `sign` gets -1 for a negative direction,
/// by which the data must be multiplied so the channel's DOF is positive), quantity from the ordinate's specific
/// data type (8 displacement, 11 velocity, 12 acceleration, 9 and 13 force; 13 marks an input), unit and name.
Channel uff_channel(const Uff58& d, double* sign);
/// The reference DOF of a 58 dataset (record 6 fields 9-10; node 0 or direction 0 = none given).
bool uff_reference(const Uff58& d, MeasuredDof* dof);

/// The time responses (function type 1) of a file as a Recording: one channel per response DOF (node,
/// direction; negative directions flip the data so the channel's DOF is positive), quantity from the ordinate's
/// specific data type (8 displacement, 11 velocity, 12 acceleration, 9 and 13 force; 13 marks an input). A DOF
/// that occurs again starts a further record. All must share the sampling interval and length.
Recording uff_recording(const UffFile& f);
/// The FRFs (function type 4) of a file: outputs = distinct response DOFs, inputs = distinct reference DOFs,
/// all on the same frequency grid; every output/input pair must be present. Multiple coherence (type 26) per
/// output is taken when present for every output.
FrfData uff_frf(const UffFile& f);
/// The same over several files (one FRF per file, one file per reference, ...): their FRFs together.
FrfData uff_frf(const std::vector<const UffFile*>& files);
/// Applies the coordinate systems of `geometry` (its 18/2420 systems and its 15/2411 nodes' displacement systems)
/// to the 55 and 2414 vectors of `data` that are not yet in global directions (data files without their own
/// geometry). Notes go to data->notes. parse_uff() does this with the file's own datasets.
void uff_apply_coordinate_systems(UffFile* data, const UffFile& geometry);

/// The modes (55, analysis type 2, 3 or 7) of a file. Complex shapes are rotated to their largest component and
/// the real part is kept. DOFs that are exactly zero in every mode are left out (UFF 55 has no "not measured").
/// FE mode shapes of dataset 2414 (data at nodes, analysis type 2, 3 or 7, three- or six-DOF vectors) count as
/// modes too.
ModalData uff_modal_data(const UffFile& f);

/// 58 datasets for a Recording (one per record and channel; ASCII or binary) / an FrfData (one per output/input
/// pair, plus multiple coherence if present) / 55 datasets for ModalData (real modes; 6 values per node if any
/// DOF is a rotation, else 3). Written with write_file_atomic.
std::vector<UffDataset> uff_datasets(const Recording& r, bool binary);
std::vector<UffDataset> uff_datasets(const FrfData& h, bool binary);
std::vector<UffDataset> uff_datasets(const ModalData& m);
void write_uff58_recording(const std::string& path, const Recording& r, bool binary, bool overwrite);
void write_uff58_frf(const std::string& path, const FrfData& h, bool binary, bool overwrite);
void write_uff55(const std::string& path, const ModalData& m, bool overwrite);

}  // namespace dynid
