// dynid/io/mat_file.hpp -- MATLAB .mat files (v5 / v7 compressed and v4: dynid's own readers; v7.3 HDF5: libmatio): the
// variables a case file names, read as matrices, sparse matrices, numbers and text, and the three things dynid
// takes from them (docs/matrix-input.md, docs/case-file.md):
//   a matrix model   K and M (sparse or dense), group matrices, element matrices, the DOF and node tables;
//   a recording      channels x samples with a sampling rate;
//   modal data       frequencies (or eigenvalues), shapes (DOFs x modes) and the DOF labels.
// Every error is an InputError naming the file and the variable, and what shape or type was expected.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/recording.hpp"
#include "dynid/io/limits.hpp"
#include "dynid/io/matrix_model.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// An open .mat file (read only). Not thread-safe: one object per thread.
class MatFile {
 public:
  /// Opens `path`; throws InputError if it is missing or not a MATLAB file. Variables of more than
  /// `limits.max_mat_elements` elements are refused when read.
  explicit MatFile(const std::string& path, const ReaderLimits& limits = {});
  ~MatFile();
  MatFile(const MatFile&) = delete;
  MatFile& operator=(const MatFile&) = delete;

  const std::string& path() const { return path_; }
  const ReaderLimits& limits() const { return limits_; }
  /// "MATLAB 5.0 (v5/v7)", "MATLAB 7.3 (HDF5)" or "MATLAB 4".
  std::string version() const;

  struct Info {
    std::string name;
    std::string type;                ///< "double", "single", "int32", ..., "sparse", "char", "cell", "struct", "logical"
    std::vector<std::size_t> dims;
    bool complex = false;
  };
  /// Every variable, in file order (headers only; no data is read).
  std::vector<Info> variables() const;
  bool has(const std::string& name) const;
  /// "K0 (946 x 946 double), M0 (946 x 946 sparse)": for messages.
  std::string listing() const;

  /// A real numeric variable (any numeric class, logical, or sparse) as a dense matrix; vectors keep their
  /// stored orientation. `what` says what the variable is for, in messages ("the stiffness matrix K").
  Eigen::MatrixXd matrix(const std::string& name, const std::string& what) const;
  /// A real numeric variable as a vector (1 x n or n x 1).
  Eigen::VectorXd vector(const std::string& name, const std::string& what) const;
  /// A real square matrix (sparse or dense) in dynid's CSC storage.
  SparseMatrix sparse(const std::string& name, const std::string& what) const;
  /// A real scalar.
  double scalar(const std::string& name, const std::string& what) const;
  /// Text: a char array (one string per row) or a cell array of char arrays.
  std::vector<std::string> strings(const std::string& name, const std::string& what) const;
  /// A cell array of real matrices (element matrices), in MATLAB's linear (column-major) order.
  std::vector<Eigen::MatrixXd> matrices(const std::string& name, const std::string& what) const;

 private:
  struct Handle;
  std::string path_;
  ReaderLimits limits_;
  std::unique_ptr<Handle> h_;
};

/// Variable names of a matrix model in a .mat file (case files: model: matrices: {mat: FILE, K: VAR, ...}).
struct MatModelNames {
  std::string file;
  std::string K, M;                   ///< assembled matrices (optional; both or neither)
  struct Group {
    std::string name, K, M;           ///< group name, its stiffness and (optional) mass variable
  };
  std::vector<Group> groups;          ///< group matrices on the global equations
  std::string element_K, element_M;   ///< cell arrays of element matrices (optional)
  std::string element_dofs;           ///< cell array of 1-based equation vectors, one per element
  std::string element_groups;         ///< optional cell array of group names, one per element
  std::string dofs;                   ///< n x 2 [node, dof 1..6] (optional: equation i is ux of node i)
  std::string nodes;                  ///< m x 3 or m x 4 [id, x, y(, z)] (optional: nodes at the origin)
};
/// Reads the model's matrices. Without a DOF table each equation becomes DOF ux of its own node (ids 1..n) at
/// the origin, and a note says so: modal analysis, detection on elements and updating of groups work, but
/// plots and geometric discovery candidates mean nothing.
/// Elements beyond `limits.max_element_dofs` DOFs are refused.
MatrixModelData read_mat_matrix_model(const MatModelNames& names, std::vector<std::string>* notes = nullptr,
                                      const ReaderLimits& limits = {});

/// Variable names of a recording ("data" channels x samples, "fs" Hz, optional "channels" labels).
struct MatRecordingNames {
  std::string file;
  std::string data = "data";          ///< channels x samples (one record), or a cell array of them (records)
  std::string sample_rate = "fs";     ///< scalar, Hz
  double sample_rate_hz = 0;          ///< > 0: given as a number instead of a variable
  std::string channels = "channels";  ///< optional: DOF labels ("13uy"), one per channel
  std::vector<std::string> channel_labels;  ///< given in the case instead of a variable
  std::vector<std::string> inputs;    ///< labels of the channels that are input forces
  std::string quantity = "acceleration";  ///< of the other channels
};
Recording read_mat_recording(const MatRecordingNames& names, const ReaderLimits& limits = {});

/// Variable names of modal data ("frequency_hz" or "eigenvalues" (rad/s)^2, "shapes" DOFs x modes, "dofs").
struct MatModalNames {
  std::string file;
  std::string frequency_hz = "frequency_hz";
  std::string eigenvalues;            ///< instead of frequency_hz: lambda = omega^2
  std::string shapes = "shapes";
  std::string dofs = "dofs";          ///< DOF labels (text), n x 2 [node, dof 1..6], or a vector of equation
                                      ///< numbers of a matrix model without a DOF table (equation q = ux of node q)
  std::string dofs_file;              ///< the file holding `dofs` when not `file` (e.g. the model's .mat)
  std::string damping;                ///< optional damping ratios
  std::string frequency_std;          ///< optional std of each frequency (Hz)
  std::string eigenvalue_std;         ///< optional std of each eigenvalue ((rad/s)^2), instead of frequency_std
  std::string shape_std;              ///< optional std of each shape entry (DOFs x modes, units of `shapes`; 0 =
                                      ///< exact, the normalising entry), or one per mode (relative to its largest)
};
ModalData read_mat_modal_data(const MatModalNames& names, const ReaderLimits& limits = {});

}  // namespace dynid
