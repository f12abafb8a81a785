// dynid/io/test_data.hpp -- plain-text test data: time histories, FRFs, LabVIEW .lvm, and a front door.
//
// Text tables (.txt, .csv, .dat, .tsv): one row per sample, fields separated by blanks, tabs or commas.
// Lines starting with '#' and blank lines are ignored. An optional first row of names (any non-numeric field)
// names the columns. Every row must have the same number of numeric fields.
//   time histories   first column time [s] (evenly spaced; the sampling rate is (n - 1) / (t_last - t_first)),
//                    the others channels; or, with a sampling rate given, every column is a channel.
//   FRF              columns frequency [Hz], then real part, imaginary part of each FRF (one or more pairs),
//                    whose output and input DOFs the caller gives (e.g. tool-impact-test/frf_point_N.txt).
//   spectrum         columns frequency [Hz], then magnitudes (linear, PSD or dB), no phase: peak picking only.
// Which one a table is, unless the caller says (read_test_data's `kind`), is read from the table itself
// (classify_text_table):
//   1. the header, when it names it: an abscissa called time/t/s/sec... is time, freq/frequency/hz is frequency;
//      data columns named re.../real... and im.../imag... are FRF pairs; fft/spectrum/psd/db/magnitude a spectrum.
//   2. else the numbers: an FRF's real and imaginary parts are one causal function (Kramers-Kronig): the inverse
//      DFT of re + i im over the lines puts its energy in one half of the lag axis (frf_causality >= 0.5;
//      measured 0.90..0.95 on the five real tool FRFs), while two time channels spread it over both halves
//      (0.00..0.07 on the real impact record and on virtual impact, random and ambient records; 0.27 for a
//      shaker's drive voltage and force, two phase-shifted sines, the closest a time record comes: two sines in
//      exact quadrature would pass, so give --as time for such a file). A table of 1 + 2k columns whose every
//      pair passes is FRFs.
//   3. else, every data column of one sign (all >= 0: magnitude or PSD; all <= 0: levels in dB below a
//      reference) is a spectrum: a vibration signal about zero takes both signs.
//   4. else time histories.
// Channel names that hold a DOF label ("5uy", "acc 5uy", "17ux force") give the channel its DOF.
// LabVIEW measurement files (.lvm, text): a file header and a segment header, each ending with a line
// "***End_of_Header***", then a line of column names ("X_Value", channel names, maybe "Comment") and rows.
// The segment header gives Channels, Samples, Y_Unit_Label, X_Dimension, X0 and Delta_X per channel;
// X_Columns says whether there is one X column (One), one before each channel (Multi) or none (No).
// The X column is used when present (Delta_X in headers is sometimes stale, e.g. after downsampling).
// Spectra (a channel name with "FFT", "spectrum" or "PSD", or X_Dimension "Frequency") come back as a table;
// time data as a Recording. Only single-segment files are read.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dynid/engine/recording.hpp"
#include "dynid/io/limits.hpp"
#include "dynid/io/uff.hpp"

namespace dynid {

/// Columns of numbers against an abscissa (time or frequency).
struct TextTable {
  std::string x_name;               ///< name of the abscissa column ("" if none was given)
  std::vector<std::string> names;   ///< one per column of `columns`
  std::vector<std::string> units;   ///< one per column ("" if unknown)
  Eigen::VectorXd x;                ///< abscissa
  Eigen::MatrixXd columns;          ///< rows x columns
  double dx = 0;                    ///< mean abscissa step, (x_last - x_first) / (rows - 1)
  std::string source;
};

/// Reads a text table whose first column is the abscissa (`x_column`), or, without one, just columns.
/// Errors name the file, the line and the column (non-numeric cell, wrong number of fields).
TextTable read_text_table(const std::string& path, bool x_column = true);
/// The same from a file's content held in memory; `name` names it in messages.
TextTable parse_text_table(const std::string& text, const std::string& name, bool x_column = true);

/// Checks that x is evenly spaced: each step within 2 % of the first, which must be > 0 (text files round their
/// abscissa). `line_of[k]` is the file line of sample k. Throws InputError naming the line where the step
/// changes. Returns the mean step (x_last - x_first) / (n - 1).
double check_even_steps(const Eigen::VectorXd& x, const std::vector<int>& line_of, const std::string& what);

/// A time history from a text table: first column time, or every column a channel when `sample_rate_hz` > 0.
/// Channels are named from the header (else "ch1", "ch2", ...); quantities are guessed from the names
/// ("force" -> input force, "acc" -> acceleration, "vel" -> velocity, "disp" -> displacement).
Recording read_time_text(const std::string& path, double sample_rate_hz = 0);

/// What a text table holds (see the header comment for the rules).
enum class TableKind { kAuto, kTimeHistory, kFrf, kSpectrum };
const char* to_string(TableKind k);  // "time history", "FRF", "spectrum", "auto"
/// The kind of a table read with its abscissa column; `why` (if not null) gets the rule that decided, in words.
TableKind classify_text_table(const TextTable& t, std::string* why = nullptr);
/// The causality measure of rule 2 for one (real, imaginary) column pair: |E+ - E-| / (E+ + E-) of the inverse
/// DFT of (i k)^p (re + i im) over the lines k, the largest over p = 0, 1, 2 (1 = causal, one-sided; ~0 =
/// unrelated columns).
double frf_causality(const Eigen::VectorXd& re, const Eigen::VectorXd& im);

/// FRFs from tables of frequency, (real, imaginary) pairs: pair j of all tables in order is FRF k, output
/// `outputs[k]` over input `inputs[k]` (a list of one applies to all). All must share the frequency grid; every
/// distinct output needs an FRF for every distinct input (missing pairs are named).
FrfData frf_of_tables(const std::vector<TextTable>& tables, const std::vector<MeasuredDof>& outputs,
                      const std::vector<MeasuredDof>& inputs);

/// One FRF from a text file of frequency, real, imaginary columns.
FrfData read_frf_text(const std::string& path, const MeasuredDof& output, const MeasuredDof& input);
/// Several FRF files into one FrfData: file k is output `outputs[k]` over input `inputs[k]`. All must share the
/// frequency grid; every distinct output needs a file for every distinct input (missing pairs are named).
FrfData read_frf_text_set(const std::vector<std::string>& paths, const std::vector<MeasuredDof>& outputs,
                          const std::vector<MeasuredDof>& inputs);

/// A LabVIEW .lvm file.
struct LvmFile {
  bool spectrum = false;   ///< a spectrum (see the header comment): use `table`
  TextTable table;         ///< always filled (x and the channels)
  Recording recording;     ///< time data (when !spectrum)
  double header_delta_x = 0;  ///< Delta_X of the header, for comparison with table.dx
};
LvmFile read_lvm(const std::string& path);
/// The same from a file's content held in memory; `name` names it in messages.
LvmFile parse_lvm(const std::string& bytes, const std::string& name);

/// What a test-data file holds, chosen by extension (.uff/.unv, .lvm, .txt/.csv/.dat/.tsv) or, failing that,
/// by content; for text tables, by classify_text_table unless `kind` says.
struct TestData {
  enum class Kind { kUff, kTimeHistory, kSpectrum, kFrf };
  Kind kind = Kind::kUff;
  UffFile uff;             ///< kUff
  Recording recording;     ///< kTimeHistory
  TextTable table;         ///< kSpectrum, kFrf (frequency, re/im pairs), and the raw table of .lvm files
  std::string how;         ///< for text tables: the rule that decided the kind, in words
};
/// `sample_rate_hz` > 0: text files have no time column (they are time histories). `kind` other than kAuto says
/// what a text table holds. `.mat` recordings are read within `limits`.
TestData read_test_data(const std::string& path, double sample_rate_hz = 0, TableKind kind = TableKind::kAuto,
                        const ReaderLimits& limits = {});

}  // namespace dynid
