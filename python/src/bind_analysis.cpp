// The engine from Python: modal analysis, correlation, SEREP, residual forces, detection, updating, discovery,
// virtual tests and identification. Results mirror the results JSON (built by io, so they follow it) with NumPy
// arrays added for the large parts. The GIL is released while the engine works.
#include <cmath>
#include <memory>
#include <optional>

#include "bindings.hpp"
#include "convert.hpp"
#include "dynid/engine/correlation.hpp"
#include "dynid/engine/detect.hpp"
#include "dynid/engine/discovery.hpp"
#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/residual_force.hpp"
#include "dynid/engine/serep.hpp"
#include "dynid/engine/virtual_test.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/discover_io.hpp"
#include "dynid/io/identify_io.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/output.hpp"
#include "dynid/io/results_json.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/eigen.hpp"

namespace dynid::python {

namespace {

using GilRelease = py::gil_scoped_release;

EigenOptions eigen_options(Options& o, EigenOptions e) {
  int modes = 0;
  if (o.get("modes", &modes)) {
    if (modes < 1) throw InputError(o.what() + ": modes must be >= 1");
    e.num_modes = modes;
    e.band_lo = e.band_hi = std::numeric_limits<double>::quiet_NaN();
  }
  std::vector<double> band;
  if (o.get("band_hz", &band)) {
    if (band.size() != 2 || !(band[0] >= 0 && band[1] > band[0]))
      throw InputError(o.what() + ": band_hz must be [lo, hi] with 0 <= lo < hi");
    e.band_lo = hz_to_eigenvalue(band[0]);
    e.band_hi = hz_to_eigenvalue(band[1]);
  }
  double shift_hz = 0;
  if (o.get("shift_hz", &shift_hz)) e.shift = hz_to_eigenvalue(shift_hz);
  std::string method;
  if (o.get("method", &method)) {
    if (method == "auto") e.method = EigenOptions::Method::kAuto;
    else if (method == "sparse") e.method = EigenOptions::Method::kSparse;
    else if (method == "dense") e.method = EigenOptions::Method::kDense;
    else throw InputError(o.what() + ": method must be auto, sparse or dense");
  }
  o.get("tolerance", &e.tolerance);
  return e;
}

py::dict modal_dict(const std::string& name, ModalResult r, const Model* model) {
  py::dict d = to_python(modal_json(name, r)).cast<py::dict>();
  Eigen::Matrix<bool, Eigen::Dynamic, 1> rigid(static_cast<Eigen::Index>(r.rigid_body.size()));
  for (std::size_t k = 0; k < r.rigid_body.size(); ++k) rigid[static_cast<Eigen::Index>(k)] = r.rigid_body[k] != 0;
  d["frequency_hz"] = move_array(std::move(r.frequencies_hz));
  d["eigenvalues"] = move_array(std::move(r.eigenvalues));
  d["shapes"] = move_array(std::move(r.modes));
  d["rigid_body"] = move_array(std::move(rigid));
  d["residuals"] = move_array(std::move(r.residuals));
  if (model) d["dof_labels"] = dof_labels(all_dofs(*model));
  d["ok"] = r.ok();
  return d;
}

// A modal() result back into a ModalResult (for sample_modes, simulate_test).
ModalResult modal_result_from(py::dict d, const Model& m) {
  ModalResult r;
  for (const char* k : {"eigenvalues", "frequency_hz", "shapes"})
    if (!d.contains(k)) throw InputError(std::string("modes: '") + k + "' is missing (pass the result of dynid.modal)");
  r.eigenvalues = d["eigenvalues"].cast<Eigen::VectorXd>();
  r.frequencies_hz = d["frequency_hz"].cast<Eigen::VectorXd>();
  r.modes = d["shapes"].cast<Eigen::MatrixXd>();
  if (r.modes.rows() != m.num_dofs() || r.modes.cols() != r.eigenvalues.size())
    throw InputError("modes: shapes are " + std::to_string(r.modes.rows()) + " x " + std::to_string(r.modes.cols()) + "; the model has " +
                     std::to_string(m.num_dofs()) + " DOFs and " + std::to_string(r.eigenvalues.size()) + " eigenvalues are given");
  r.rigid_body.assign(static_cast<std::size_t>(r.eigenvalues.size()), 0);
  if (d.contains("rigid_body")) {
    const auto rb = d["rigid_body"].cast<std::vector<bool>>();
    for (std::size_t k = 0; k < rb.size() && k < r.rigid_body.size(); ++k) r.rigid_body[k] = rb[k];
  }
  r.residuals = Eigen::VectorXd::Zero(r.eigenvalues.size());
  r.dofs = m.num_dofs();
  r.summary.status = EigenStatus::kSuccess;
  return r;
}

// K and M with one shared pattern (the engine's sparse routines need it).
void share_pattern(SparseMatrix* K, SparseMatrix* M) {
  if (K->rows() != M->rows()) throw InputError("K is " + std::to_string(K->rows()) + " x " + std::to_string(K->cols()) + " but M is " +
                                               std::to_string(M->rows()) + " x " + std::to_string(M->cols()));
  SparseMatrix k = *K + 0.0 * *M, m = *M + 0.0 * *K;
  k.makeCompressed();
  m.makeCompressed();
  *K = std::move(k);
  *M = std::move(m);
}

Eigen::VectorXd vec(py::handle h, const char* what) {
  try {
    return h.cast<Eigen::VectorXd>();
  } catch (const py::cast_error&) {
    throw InputError(std::string(what) + ": expected a 1-D array of numbers");
  }
}

py::dict detect_result(const std::string& name, DetectSummary S) {
  py::dict d = to_python(detect_json(name, S)).cast<py::dict>();
  d["residual_dofs"] = dof_labels(S.dofs);
  d["residuals"] = move_array(std::move(S.residuals));
  d["pseudo"] = move_array(std::move(S.pseudo));
  d["delta_pseudo"] = move_array(std::move(S.delta_pseudo));
  return d;
}

IdentificationOptions identification_options(Options& o, std::string* method) {
  IdentificationOptions io;
  o.get("method", method);
  if (!method->empty() && *method != "lscf" && *method != "ssi") throw InputError(o.what() + ": method must be lscf or ssi");
  std::vector<double> v;
  if (o.get("band_hz", &v)) {
    if (v.size() != 2) throw InputError(o.what() + ": band_hz must be [lo, hi]");
    io.band_lo_hz = v[0];
    io.band_hi_hz = v[1];
  }
  if (o.get("orders", &v)) {
    if (v.size() != 2) throw InputError(o.what() + ": orders must be [min, max]");
    io.min_order = static_cast<int>(v[0]);
    io.max_order = static_cast<int>(v[1]);
  }
  o.get("order_step", &io.order_step);
  o.get("stable_frequency", &io.stable_frequency);
  o.get("stable_damping", &io.stable_damping);
  o.get("cluster_damping", &io.cluster_damping);
  o.get("stable_mac", &io.stable_mac);
  o.get("max_damping", &io.max_damping);
  o.get("min_cluster_fraction", &io.min_cluster_fraction);
  o.get("cluster_tolerance", &io.cluster_tolerance);
  o.get("block_rows", &io.block_rows);
  o.get("decimate", &io.decimate);
  std::string why;
  if (!io.IsValid(&why)) throw InputError(o.what() + ": " + why);
  return io;
}

py::dict identification_result(IdentificationSummary s) {
  py::dict d = to_python(identification_json(s)).cast<py::dict>();
  d["modal_data"] = from_modal_data(s.modal_data("dynid identify " + s.method));
  return d;
}

}  // namespace

void bind_analysis(py::module_& mod) {
  mod.def("_modal_case", [](std::shared_ptr<Case> c, py::dict kw) {
    Options o(kw, "dynid.modal");
    EigenOptions e = eigen_options(o, c->analysis.eigen_options());
    o.finish();
    ModalResult r;
    {
      GilRelease nogil;
      r = modal_analysis(c->model, e);
    }
    return modal_dict(c->name, std::move(r), &c->model);
  });
  mod.def("_modal_model", [](std::shared_ptr<Model> m, py::dict kw) {
    Options o(kw, "dynid.modal");
    std::string name = "model";
    o.get("name", &name);
    EigenOptions e = eigen_options(o, EigenOptions{});
    o.finish();
    ModalResult r;
    {
      GilRelease nogil;
      r = modal_analysis(*m, e);
    }
    return modal_dict(name, std::move(r), m.get());
  });
  mod.def("_solve_eigen", [](py::handle K, py::handle M, py::dict kw) {
    SparseMatrix k = to_sparse(K, "K"), m = to_sparse(M, "M");
    share_pattern(&k, &m);
    Options o(kw, "dynid.solve_eigen");
    EigenOptions e = eigen_options(o, EigenOptions{});
    o.get("allow_singular_stiffness", &e.allow_singular_stiffness);
    o.finish();
    EigenSolution s;
    {
      GilRelease nogil;
      s = solve_eigen(k, m, e);
    }
    py::dict d;
    Eigen::VectorXd f(s.eigenvalues.size());
    for (Eigen::Index i = 0; i < f.size(); ++i) f[i] = eigenvalue_to_hz(s.eigenvalues[i]);
    d["frequency_hz"] = move_array(std::move(f));
    d["eigenvalues"] = move_array(std::move(s.eigenvalues));
    d["shapes"] = move_array(std::move(s.modes));
    d["residuals"] = move_array(std::move(s.residuals));
    d["ok"] = s.summary.ok();
    d["message"] = s.summary.message;
    d["method"] = s.summary.method;
    return d;
  });

  mod.def("mac", [](const Eigen::Ref<const Eigen::MatrixXd>& A, const Eigen::Ref<const Eigen::MatrixXd>& B) {
    return move_array(mac_matrix(A, B));
  }, py::arg("A"), py::arg("B"), "MAC matrix of the columns of A (dofs x ma) and B (dofs x mb).");
  mod.def(
      "pair_modes",
      [](const Eigen::Ref<const Eigen::MatrixXd>& mac, py::object fa, py::object fb, double min_mac, double max_ratio) {
        const Pairing p = pair_modes(mac, fa.is_none() ? Eigen::VectorXd() : vec(fa, "fa"),
                                     fb.is_none() ? Eigen::VectorXd() : vec(fb, "fb"), min_mac, max_ratio);
        py::list pairs;
        for (const ModePair& q : p.pairs) {
          py::dict d;
          d["a"] = q.a;
          d["b"] = q.b;
          d["mac"] = q.mac;
          d["freq_error"] = q.freq_error;
          pairs.append(d);
        }
        py::dict d;
        d["pairs"] = pairs;
        d["unpaired_a"] = p.unpaired_a;
        d["unpaired_b"] = p.unpaired_b;
        return d;
      },
      py::arg("mac"), py::arg("fa") = py::none(), py::arg("fb") = py::none(), py::arg("min_mac") = 0.5,
      py::arg("max_ratio") = 0.0,
      "One-to-one pairing of the columns of A and B by the score MAC - |f_b - f_a| / f_a when frequencies fa, fb are "
      "given (a per cent of frequency weighs like 0.01 of MAC; partners more than 2x apart never pair), by MAC alone "
      "otherwise (correlation.hpp).");
  mod.def("serep", [](const Eigen::Ref<const Eigen::MatrixXd>& Phi, const Eigen::Ref<const Eigen::VectorXd>& lambda, std::vector<int> masters,
                      double rcond) {
    SerepReduction s;
    {
      GilRelease nogil;
      s = serep_reduce(Phi, lambda, masters, rcond);
    }
    py::dict d;
    d["masters"] = s.masters;
    d["T"] = move_array(std::move(s.T));
    d["P"] = move_array(std::move(s.P));
    d["K"] = move_array(std::move(s.K));
    d["M"] = move_array(std::move(s.M));
    d["modes"] = s.modes;
    d["rank"] = s.rank;
    d["condition"] = s.condition;
    return d;
  }, py::arg("Phi"), py::arg("eigenvalues"), py::arg("masters"), py::arg("rcond") = 1e-8,
     "SEREP reduction (paper eq. 1) to the master equations: {'T', 'P', 'K', 'M', 'rank', 'condition'}.");
  mod.def("residual_forces", [](py::handle K, py::handle M, const Eigen::Ref<const Eigen::VectorXd>& lambda,
                                const Eigen::Ref<const Eigen::MatrixXd>& Phi) {
    const bool dense = py::isinstance<py::array>(K) && py::isinstance<py::array>(M);
    if (Phi.cols() != lambda.size())
      throw InputError("residual_forces: " + std::to_string(lambda.size()) + " eigenvalues for " + std::to_string(Phi.cols()) + " shapes");
    if (dense) {
      const Eigen::MatrixXd k = K.cast<Eigen::MatrixXd>(), m = M.cast<Eigen::MatrixXd>();
      if (k.rows() != Phi.rows() || m.rows() != Phi.rows()) throw InputError("residual_forces: K, M and Phi disagree in size");
      return move_array(residual_forces(k, m, Eigen::VectorXd(lambda), Eigen::MatrixXd(Phi)));
    }
    SparseMatrix k = to_sparse(K, "K"), m = to_sparse(M, "M");
    share_pattern(&k, &m);
    if (k.rows() != Phi.rows()) throw InputError("residual_forces: K is " + std::to_string(k.rows()) + " x " + std::to_string(k.cols()) +
                                                 " but Phi has " + std::to_string(Phi.rows()) + " rows");
    Eigen::MatrixXd R;
    {
      GilRelease nogil;
      R = residual_forces(k, m, Eigen::VectorXd(lambda), Eigen::MatrixXd(Phi));
    }
    return move_array(std::move(R));
  }, py::arg("K"), py::arg("M"), py::arg("eigenvalues"), py::arg("Phi"),
     "Eq. (6): R_i = (-K + lambda_i M) phi_i for sparse (scipy) or dense (NumPy) K and M.");
  mod.def("pseudo_residual_force", [](const Eigen::Ref<const Eigen::MatrixXd>& R) { return move_array(pseudo_residual_force(R)); },
          py::arg("R"), "Eqs. (7)-(8): per DOF the geometric mean over the modes of |R|.");

  // A model's residual-force operator: K and M assembled once, then eq. (6) for any (lambda, Phi). The loop of
  // an SHM application (one evaluation per measurement) pays neither assembly nor conversion.
  struct ResidualOperator {
    SparseMatrix K, M;
    std::vector<int> rows;  // equations of the measured DOFs, or empty (full)
  };
  py::class_<ResidualOperator>(mod, "ResidualForces", "Eq. (6) on a model's K and M, assembled once.")
      .def(py::init([](const Model& m) {
        GilRelease nogil;
        AssembledSystem s = assemble_system(m);
        return ResidualOperator{std::move(s.K), std::move(s.M), {}};
      }), py::arg("model"))
      .def("__call__", [](const ResidualOperator& op, const Eigen::Ref<const Eigen::VectorXd>& lambda, const Eigen::Ref<const Eigen::MatrixXd>& Phi) {
        if (Phi.rows() != op.K.rows() || Phi.cols() != lambda.size())
          throw InputError("ResidualForces: Phi must be " + std::to_string(op.K.rows()) + " x (modes) with one eigenvalue per column");
        Eigen::MatrixXd R;
        residual_forces(op.K, op.M, Eigen::MatrixXd(Phi), Eigen::VectorXd(lambda), &R);
        return move_array(std::move(R));
      }, py::arg("eigenvalues"), py::arg("Phi"), "R (dofs x modes) for eigenvalues lambda and shapes Phi (all DOFs).")
      .def_property_readonly("K", [](const ResidualOperator& op) { return from_sparse(op.K); })
      .def_property_readonly("M", [](const ResidualOperator& op) { return from_sparse(op.M); });

  mod.def("sample_modes", [](std::shared_ptr<Model> m, py::dict modes, py::handle dofs, int first, int count, const std::string& source) {
    const ModalResult r = modal_result_from(modes, *m);
    const std::vector<MeasuredDof> d = to_dofs(dofs, "sample_modes dofs", m.get());
    if (count < 0) count = static_cast<int>(r.eigenvalues.size()) - first;
    return from_modal_data(sample_modes(*m, r, d, first, count, source));
  }, py::arg("model"), py::arg("modes"), py::arg("dofs") = "all", py::arg("first") = 0, py::arg("count") = -1,
     py::arg("source") = "dynid.sample_modes", "A model's modes at DOFs, as a test sees them (modal data).");

  mod.def("_detect", [](std::shared_ptr<Case> c, py::object measured, py::object reference, std::shared_ptr<Model> simulated_changed) {
    if (!c->detect) throw InputError(c->path + ": the case has no detect: section (see docs/case-file.md)");
    DetectSummary S;
    if (measured.is_none()) {
      GilRelease nogil;
      S = detect_case(*c);
    } else {
      DetectOptions opt = c->detect->options;
      const ModalData data = to_modal_data(measured, "detect measured");
      std::optional<ModalData> ref;
      if (!reference.is_none()) ref = to_modal_data(reference, "detect reference_measured");
      if (simulated_changed) opt.simulated_changed = simulated_changed.get();
      GilRelease nogil;
      S = detect(c->model, data, opt, ref ? &*ref : nullptr);
    }
    return detect_result(c->name, std::move(S));
  });

  mod.def("_update", [](std::shared_ptr<Case> c, py::object measured) {
    if (!c->update) throw InputError(c->path + ": the case has no update: section (see docs/case-file.md)");
    UpdateRun run;
    std::optional<ModalData> data;
    if (!measured.is_none()) data = to_modal_data(measured, "update measured");
    {
      GilRelease nogil;
      run = update_case(*c, data ? &*data : nullptr);
    }
    py::dict d = to_python(update_json(c->name, *run.pm, *c->update, run.fit, run.search ? &*run.search : nullptr,
                                       run.lcurve ? &*run.lcurve : nullptr))
                     .cast<py::dict>();
    d["theta"] = move_array(Eigen::VectorXd(run.fit.theta));
    return d;
  });

  mod.def("_discover", [](std::shared_ptr<Case> c, py::object measured, py::object recordings) {
    if (!c->discover) throw InputError(c->path + ": the case has no discover: section (see docs/case-file.md)");
    DiscoveryData data;
    if (!measured.is_none()) {
      ModalData m = to_modal_data(measured, "discover measured");
      const std::string source = m.source;
      GilRelease nogil;
      data = discovery_data(*c, std::move(m), source);
    } else if (!recordings.is_none()) {
      std::vector<Recording> recs;
      int k = 0;
      for (py::handle r : py::reinterpret_borrow<py::sequence>(recordings)) recs.push_back(to_recording(r, "discover recording " + std::to_string(++k)));
      GilRelease nogil;
      data = discovery_data(*c, std::move(recs), "recordings from Python");
    } else {
      GilRelease nogil;
      data = discovery_data(*c, 0);
    }
    DiscoverySummary s;
    std::unique_ptr<ExpectCheck> check;
    {
      GilRelease nogil;
      s = discover(c->model, data.measured, c->discover->options);
      if (c->discover->expect)
        check = std::make_unique<ExpectCheck>(check_expectation(*c->discover->expect, s, c->model));
    }
    py::dict d = to_python(discovery_json(*c, data, s, check.get())).cast<py::dict>();
    return d;
  });

  mod.def("_simulate_test", [](std::shared_ptr<Case> c, std::uint64_t seed_offset) {
    if (!c->test) throw InputError(c->path + ": the case has no test: section (see docs/case-file.md)");
    VirtualTest vt;
    {
      GilRelease nogil;
      vt = run_test_spec(c->model, *c->test, c->analysis.eigen_options(), seed_offset, "modal analysis ");
    }
    py::list recs;
    for (Recording& r : vt.recordings) recs.append(from_recording(std::move(r)));
    py::dict d;
    d["recordings"] = recs;
    d["truth"] = from_modal_data(std::move(vt.modes));
    py::dict id;
    id["method"] = c->test->method;
    if (c->test->identify.band_hi_hz > 0) id["band_hz"] = std::vector<double>{c->test->identify.band_lo_hz, c->test->identify.band_hi_hz};
    if (c->test->identify.max_order > 0) id["orders"] = std::vector<int>{c->test->identify.min_order, c->test->identify.max_order};
    d["identify"] = id;
    return d;
  });

  mod.def("_identify", [](py::object recordings, py::object frf, py::dict kw) {
    Options o(kw, "dynid.identify");
    std::string method;
    const IdentificationOptions io = identification_options(o, &method);
    o.finish();
    IdentificationSummary s;
    if (!frf.is_none()) {
      std::vector<FrfData> sets;
      if (py::isinstance<py::dict>(frf)) sets.push_back(to_frf(frf, "identify frf"));
      else {
        int k = 0;
        for (py::handle f : py::reinterpret_borrow<py::sequence>(frf)) sets.push_back(to_frf(f, "identify frf " + std::to_string(++k)));
      }
      if (!method.empty() && method != "lscf") throw InputError("dynid.identify: FRFs are identified by lscf");
      GilRelease nogil;
      s = identify_lscf(merge_frfs(std::move(sets)), io);
    } else {
      std::vector<Recording> recs;
      if (py::isinstance<py::dict>(recordings)) recs.push_back(to_recording(recordings, "identify recording"));
      else {
        int k = 0;
        for (py::handle r : py::reinterpret_borrow<py::sequence>(recordings)) recs.push_back(to_recording(r, "identify recording " + std::to_string(++k)));
      }
      GilRelease nogil;
      s = identify_recordings(std::move(recs), method, io);
    }
    return identification_result(std::move(s));
  });

  mod.def("estimate_frf", [](py::object recordings, py::dict kw) {
    Options o(kw, "dynid.estimate_frf");
    FrfOptions fo;
    std::string est = "h1";
    o.get("estimator", &est);
    if (est != "h1" && est != "h2") throw InputError("dynid.estimate_frf: estimator must be h1 or h2");
    fo.estimator = est == "h2" ? FrfOptions::Estimator::kH2 : FrfOptions::Estimator::kH1;
    o.get("segment", &fo.segment);
    o.get("overlap", &fo.overlap);
    o.get("force_window", &fo.force_window);
    o.get("exponential_end", &fo.exponential_end);
    o.get("max_frequency_hz", &fo.max_frequency_hz);
    o.finish();
    std::string why;
    if (!fo.IsValid(&why)) throw InputError("dynid.estimate_frf: " + why);
    std::vector<Recording> recs;
    if (py::isinstance<py::dict>(recordings)) recs.push_back(to_recording(recordings, "estimate_frf recording"));
    else {
      int k = 0;
      for (py::handle r : py::reinterpret_borrow<py::sequence>(recordings)) recs.push_back(to_recording(r, "estimate_frf recording " + std::to_string(++k)));
    }
    FrfData f;
    {
      GilRelease nogil;
      f = estimate_frf(recs, fo);
    }
    return from_frf(std::move(f));
  }, py::arg("recordings"), py::arg("options"));

  mod.def("identification_band", [](std::shared_ptr<Model> m, py::handle sensors, double nyquist_hz, int modes) {
    const ModelBand b = band_from_model(*m, to_dofs(sensors, "identification_band sensors", m.get()), nyquist_hz, modes);
    py::dict d;
    d["band_hz"] = std::vector<double>{b.lo_hz, b.hi_hz};
    d["visible_hz"] = b.visible_hz;
    return d;
  }, py::arg("model"), py::arg("sensors"), py::arg("nyquist_hz"), py::arg("modes") = 8,
     "The identification band a model implies for sensors (the rule discovery uses when no band is given).");
}

}  // namespace dynid::python
