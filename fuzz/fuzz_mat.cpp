// fuzz_mat: the input is the content of a MATLAB .mat file (v4, v5/v7 with compressed variables, v7.3 HDF5) for
// MatFile (dynid's v5 and v4 readers, instrumented; libmatio for v7.3): every variable is listed and read as a
// matrix, a sparse matrix, text and a cell array of matrices, and the three readers run with their default variable
// names (a model of the first variables, a recording, modal data). The bytes go to an in-memory file (memfd), since
// libmatio reads files by name. libmatio and libhdf5 are Debian's (not instrumented): the target finds crashes and
// hangs in them and any memory error in dynid's code that interprets what they return.
#include <sys/mman.h>
#include <unistd.h>

#include "dynid/io/mat_file.hpp"
#include "fuzz_reader.hpp"

namespace {

std::string memory_file(const std::string& bytes) {
  static const int fd = memfd_create("fuzz.mat", 0);
  if (fd < 0 || ftruncate(fd, 0) != 0) return "";
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = pwrite(fd, bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (n <= 0) return "";
    done += static_cast<std::size_t>(n);
  }
  return "/proc/self/fd/" + std::to_string(fd);
}

template <class F>
void each(F f) {  // one malformed variable must not stop the others from being explored
  try {
    f();
  } catch (const dynid::InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return dynid::fuzz::feed(data, size, [](const std::string& bytes) {
    const std::string path = memory_file(bytes);
    if (path.empty()) return;
    const dynid::ReaderLimits limits = dynid::fuzz::limits();
    const dynid::MatFile f(path, limits);
    const auto vars = f.variables();
    for (const auto& v : vars) {
      each([&] { f.matrix(v.name, "fuzz"); });
      each([&] { f.sparse(v.name, "fuzz"); });
      each([&] { f.strings(v.name, "fuzz"); });
      each([&] { f.matrices(v.name, "fuzz"); });
    }
    if (vars.size() >= 2) {
      dynid::MatModelNames n;
      n.file = path;
      n.K = vars[0].name;
      n.M = vars[1].name;
      n.groups.push_back({"g", vars[0].name, vars[1].name});
      each([&] { dynid::read_mat_matrix_model(n, nullptr, limits); });
    }
    each([&] {
      dynid::MatRecordingNames r;
      r.file = path;
      dynid::read_mat_recording(r, limits);
    });
    each([&] {
      dynid::MatModalNames m;
      m.file = path;
      dynid::read_mat_modal_data(m, limits);
    });
  });
}
