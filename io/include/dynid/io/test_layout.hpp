// dynid/io/test_layout.hpp -- test data spread over files, assembled into tests.
//
// Acquisition systems export one test in many layouts: one file per channel (the force in its own file), one
// file per test, several files per hammer location, one file per hit, UFF 58 and 58b mixed, text/CSV columns.
// read_test_set reads every file given and assembles what they hold:
//
//   time histories  -> tests (one Recording each, with all its channels, inputs and outputs), by these rules:
//     1. Every channel dataset (a UFF 58 time response, a text/LabVIEW column) is a piece: its channel (DOF and
//        whether it is a force; a channel without a node is known by its name), sampling rate, sample count,
//        start time (abscissa minimum) and reference DOF (UFF 58 record 6 fields 9-10: the hammer location or
//        shaker of the test it belongs to).
//     2. Pieces without a reference, in a file that also holds responses and whose force channels are all at one
//        DOF, take that DOF as their reference (a file per hammer location written without references).
//     3. Pieces are grouped into tests by reference DOF, sampling rate and sample count. Pieces without a
//        reference join the one referenced test with their sampling and length; if there are several, the files
//        are ambiguous and that is an error naming them.
//     4. Within a test, the records (hits, runs) of each channel are its pieces in order (files in the order
//        given, datasets in file order) or, when the start times differ, one record per start time. Every channel
//        needs the same records; the channels are in the order they first appear in the files.
//   FRFs            -> one FrfData (UFF 58 type 4 of every file; text tables of frequency, re, im pairs).
//   a magnitude spectrum (no phase) -> its table (peak picking; give it alone).
// Each inconsistency is reported with the file, the dataset line (or column), what differs and what to do.
#pragma once

#include <string>
#include <vector>

#include "dynid/engine/recording.hpp"
#include "dynid/io/test_data.hpp"

namespace dynid {

struct TestSetOptions {
  TableKind kind = TableKind::kAuto;  ///< what text tables hold (kAuto: read from their content, see test_data.hpp)
  double sample_rate_hz = 0;          ///< text time tables without a time column (every column a channel)
  /// FRF text tables: output and input DOF of each FRF (pair of columns, over the files in order), or one for
  /// all. Empty: FRF k is output point k (DOF "k ux") over one common reference "0ux", with a note.
  std::vector<MeasuredDof> frf_outputs, frf_inputs;
  ReaderLimits limits;  ///< of the files read (read_test_data)
};

/// One test: the channels of one excitation set-up (a hammer location, a shaker run, an ambient run).
struct TestGroup {
  Recording recording;            ///< every channel (outputs and inputs), records aligned
  bool has_reference = false;     ///< the files gave (or rule 2 inferred) a reference DOF
  MeasuredDof reference;
  std::vector<std::string> files; ///< the files its pieces came from, in order
  bool ok = true;                 ///< false: the pieces do not make a test (see TestSet::problems)
  /// "33 outputs + force 5uy, 5 records of 4096 samples at 256 Hz, from 34 files"
  std::string summary() const;
};

struct TestSet {
  enum class Kind { kRecordings, kFrf, kSpectrum };
  Kind kind = Kind::kRecordings;
  std::vector<TestGroup> tests;   ///< kRecordings
  FrfData frf;                    ///< kFrf
  TextTable spectrum;             ///< kSpectrum
  std::vector<std::string> files; ///< every file read
  std::vector<std::string> read_as; ///< how each text or LabVIEW file was read (its kind and the rule that decided)
  std::vector<std::string> notes; ///< what else was inferred (a reference from a force channel, DOFs of FRF tables)
  /// Inconsistencies that stop identification (file, dataset line, what differs, what to do); `dynid info`
  /// lists them, identification throws them (require_consistent).
  std::vector<std::string> problems;
  /// Throws InputError with every problem, one per line, when there are any.
  void require_consistent() const;
  /// The tests' recordings (require_consistent first).
  std::vector<Recording> recordings() const;
};

/// Reads the files (read_test_data each) and assembles them.
TestSet read_test_set(const std::vector<std::string>& paths, const TestSetOptions& options = {});
/// The same for files already read (paths[k] names files[k] in messages).
TestSet assemble_test_set(const std::vector<TestData>& files, const std::vector<std::string>& paths, const TestSetOptions& options = {});

}  // namespace dynid
