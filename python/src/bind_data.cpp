// Files from Python: .mat variables, recordings and modal data in any format dynid reads, UFF files.
#include <variant>

#include "bindings.hpp"
#include "convert.hpp"

#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include "dynid/io/mat_file.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/point_map.hpp"
#include "dynid/io/test_data.hpp"
#include "dynid/io/uff.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid::python {

void bind_data(py::module_& mod) {
  mod.def("mat_variables", [](const std::filesystem::path& path_) {
    const std::string path = path_.string();
    const MatFile f(path);
    py::list out;
    for (const MatFile::Info& i : f.variables()) {
      py::dict d;
      d["name"] = i.name;
      d["type"] = i.type;
      d["shape"] = py::tuple(py::cast(i.dims));
      d["complex"] = i.complex;
      out.append(d);
    }
    return out;
  }, py::arg("path"), "The variables of a .mat file (v5/v7 or v7.3): name, type, shape.");
  mod.def("mat_version", [](const std::filesystem::path& path) { return MatFile(path.string()).version(); }, py::arg("path"));
  mod.def("read_mat", [](const std::filesystem::path& path_, const std::string& name, const std::string& as) -> py::object {
    const std::string path = path_.string();
    const MatFile f(path);
    const std::string what = "read_mat";
    if (as == "sparse") return from_sparse(f.sparse(name, what));
    if (as == "text") return py::cast(f.strings(name, what));
    if (as == "cell") {
      py::list l;
      for (Eigen::MatrixXd& m : f.matrices(name, what)) l.append(move_array(std::move(m)));
      return std::move(l);
    }
    if (as != "dense") throw InputError("read_mat: as must be 'dense', 'sparse', 'text' or 'cell'");
    return move_array(f.matrix(name, what));
  }, py::arg("path"), py::arg("name"), py::arg("as_") = "dense",
     "One variable of a .mat file: a real matrix (dense NumPy), a square matrix as scipy.sparse, text, or a cell array of matrices.");
  mod.def("read_mat_recording", [](const std::filesystem::path& path_, py::dict kw) {
    const std::string path = path_.string();
    Options o(kw, "dynid.read_mat_recording");
    MatRecordingNames n;
    n.file = path;
    o.get("data", &n.data);
    o.get("sample_rate", &n.sample_rate);
    o.get("sample_rate_hz", &n.sample_rate_hz);
    o.get("channels", &n.channels);
    o.get("channel_labels", &n.channel_labels);
    o.get("inputs", &n.inputs);
    o.get("quantity", &n.quantity);
    o.finish();
    return from_recording(read_mat_recording(n));
  }, py::arg("path"), py::arg("options"));
  mod.def("read_mat_modal_data", [](const std::filesystem::path& path_, py::dict kw) {
    const std::string path = path_.string();
    Options o(kw, "dynid.read_mat_modal_data");
    MatModalNames n;
    n.file = path;
    o.get("frequency_hz", &n.frequency_hz);
    o.get("eigenvalues", &n.eigenvalues);
    o.get("shapes", &n.shapes);
    o.get("dofs", &n.dofs);
    o.get("damping", &n.damping);
    o.finish();
    return from_modal_data(read_mat_modal_data(n));
  }, py::arg("path"), py::arg("options"));
  mod.def("read_modal_data", [](const std::filesystem::path& path_, std::shared_ptr<Model> model, const std::string& geometry) {
    const std::string path = path_.string();
    if (!model) {
      if (!geometry.empty()) throw InputError("read_modal_data: a geometry file needs the model its points are tied to");
      const TestData d = read_test_data(path);
      if (d.kind == TestData::Kind::kUff) return from_modal_data(uff_modal_data(d.uff));
      return from_modal_data(read_modal_data(path));
    }
    GeometrySpec g;
    g.file = geometry;
    std::vector<std::string> notes;
    py::dict d = from_modal_data(read_measured_modal_data(path, g, *model, &notes));
    d["notes"] = notes;
    return d;
  }, py::arg("path"), py::arg("model") = nullptr, py::arg("geometry") = "",
     "Modal data from a modal-data .json, a UFF 55/2414 file or a .mat file (dofs, frequency_hz, shapes); with a model and a "
     "geometry file (UFF 15/2411), test points are tied to model nodes.");
  mod.def("read_recording", [](const std::filesystem::path& path_, double sample_rate_hz) {
    const std::string path = path_.string();
    TestData d = read_test_data(path, sample_rate_hz);
    if (d.kind == TestData::Kind::kUff) return from_recording(uff_recording(d.uff));
    if (d.kind == TestData::Kind::kTimeHistory) return from_recording(std::move(d.recording));
    throw InputError(path + ": a spectrum, not a time recording");
  }, py::arg("path"), py::arg("sample_rate_hz") = 0.0, "A time recording from UFF 58, text/CSV, LabVIEW .lvm or .mat.");
  mod.def("read_frf", [](const std::filesystem::path& path) { return from_frf(uff_frf(read_uff(path.string()))); }, py::arg("path"),
          "FRFs (UFF 58, function type 4).");
  mod.def("write_modal_data", [](const std::filesystem::path& path_, py::handle data, bool overwrite) {
    const std::string path = path_.string();
    write_modal_data(path, to_modal_data(data, "write_modal_data"), overwrite);
  }, py::arg("path"), py::arg("data"), py::arg("overwrite") = false);
  mod.def("write_uff55", [](const std::filesystem::path& path_, py::handle data, bool overwrite) {
    const std::string path = path_.string();
    write_uff55(path, to_modal_data(data, "write_uff55"), overwrite);
  }, py::arg("path"), py::arg("data"), py::arg("overwrite") = false);
  mod.def("write_uff58", [](const std::filesystem::path& path_, py::handle rec, bool binary, bool overwrite) {
    const std::string path = path_.string();
    write_uff58_recording(path, to_recording(rec, "write_uff58"), binary, overwrite);
  }, py::arg("path"), py::arg("recording"), py::arg("binary") = true, py::arg("overwrite") = false);
}

}  // namespace dynid::python
