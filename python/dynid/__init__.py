"""dynid from Python: finds where a structure differs from its finite-element model, and why, from vibration
measurements (docs/python.md).

    import dynid
    case = dynid.load_case("cases/paper-frame")
    print(dynid.modal(case)["frequency_hz"][:4])       # Table 2: 0.6496 1.5019 2.0748 3.2737 Hz

Models come from case files (load_case), NumPy arrays (Model.from_arrays), matrices (Model.from_matrices, SciPy
sparse or NumPy) or MATLAB files (Model.from_mat). Results are plain Python objects that mirror the results JSON
of the command line (docs/results-json.md), with NumPy arrays for the large parts. Options are keyword
arguments named as the keys of the case file's sections (docs/case-file.md) and checked the same way: a wrong
key or value raises dynid.InputError with the case file's message.
"""

import json as _json
import os as _os

from . import _dynid
from ._dynid import (  # noqa: F401  (re-exported)
    Case,
    InputError,
    InternalError,
    Model,
    NumericalError,
    ResidualForces,
    __version__,
    identification_band,
    load_case,
    mac,
    mat_variables,
    mat_version,
    pair_modes,
    pseudo_residual_force,
    read_frf,
    read_mat,
    read_modal_data,
    read_recording,
    residual_forces,
    sample_modes,
    serep,
    set_threads,
    write_modal_data,
    write_uff55,
    write_uff58,
)

__all__ = [
    "Case", "InputError", "InternalError", "Model", "NumericalError", "ResidualForces", "detect", "discover",
    "estimate_frf", "identification_band", "identify", "load_case", "mac", "mat_variables", "mat_version", "modal",
    "pair_modes", "pseudo_residual_force", "read_frf", "read_mat", "read_mat_modal_data", "read_mat_recording",
    "read_modal_data", "read_recording", "residual_forces", "sample_modes", "serep", "set_threads", "simulate_test",
    "solve_eigen", "update", "write_modal_data", "write_uff55", "write_uff58",
]

_PYTHON_SOURCE = "<python>"  # stands for measured data passed as a Python object


def _jsonable(o):
    if hasattr(o, "tolist"):
        return o.tolist()
    if isinstance(o, (set, tuple)):
        return list(o)
    raise TypeError(f"{type(o).__name__} is not a valid option value")


def _case_for(model, section, options, what):
    """A Case holding `model` and one section built from keyword options (checked as a case file's)."""
    text = _json.dumps({"name": what, section: options}, default=_jsonable, indent=1)
    return _dynid._case_with_model(model, text, f"dynid.{section} options", _os.getcwd())


def _is_case(x):
    return isinstance(x, Case)


def _no_options(case, options, what):
    if options:
        raise InputError(f"dynid.{what}: a case brings its own {what}: section; options "
                         f"({', '.join(sorted(options))}) apply to a Model (pass case.model)")


# ---- models -------------------------------------------------------------------------------------------------------

def _from_arrays(nodes, elements, **options):
    """A model from NumPy arrays.

    nodes:     (n, 2) or (n, 3) coordinates; node ids 1..n unless node_ids=...
    elements:  (e, 2) node ids of each member; element ids 1..e unless element_ids=...
    Keyword options: element ('beam2d', 'frame2d' (default), 'frame3d'), element_types (one per element),
    materials {name: {E, rho, nu, G}}, sections {name: {A, I (= Iz), Iy, J, shear_factor}},
    element_material / element_section (one name for all or one per element; optional when only one is defined),
    element_groups, element_orientation ((e, 3), frame3d), supports ('free', {node: 'all' | 'pinned' | ['ux', ...]}
    or [{'nodes': [...], 'fix': ...}]), point_masses [{node, mass, inertia, id}], springs [{node | nodes, dofs, k,
    id}], mass ('consistent' | 'lumped'), rotary_inertia (bool). Copies the arrays (C order float64).
    """
    return Model._from_arrays(nodes, elements, options)


def _from_matrices(**options):
    """A model of matrix elements (docs/matrix-input.md): K and M (assembled; SciPy sparse or NumPy), groups
    {name: (K, M)} (group matrices on the global equations; M may be None), elements [{id, dofs, K, M, group}],
    dofs (one label per equation, e.g. '13uy'; default: equation i is ux of node i+1), nodes ((m, 4) [id, x, y, z];
    default: at the origin), supports, point_masses, springs. What K and M hold beyond the groups and elements
    becomes a 'remainder' element. Copies the matrices."""
    return Model._from_matrices(options)


def _from_mat(path, **names):
    """A model from a MATLAB file: variable names as in a case file's model: matrices: {mat: FILE, ...}
    (K, M, groups: [names] or {name: {K, M}}, elements: {K, M, dofs, groups}, dofs, nodes)."""
    spec = dict(names)
    spec["mat"] = _os.path.abspath(path)
    text = _json.dumps({"model": {"matrices": spec}}, default=_jsonable)
    return _dynid._model_from_case_text(text, f"dynid.Model.from_mat({path})")


Model.from_arrays = staticmethod(_from_arrays)
Model.from_matrices = staticmethod(_from_matrices)
Model.from_mat = staticmethod(_from_mat)


# ---- analyses -----------------------------------------------------------------------------------------------------

def modal(model, **options):
    """Modal analysis of a Model or Case: the modal results JSON ({'case', 'dofs', 'nonzeros', 'modes', 'solver'})
    plus NumPy arrays 'frequency_hz', 'eigenvalues', 'shapes' (free DOFs x modes, mass-normalised, not copied),
    'rigid_body', 'residuals' and 'dof_labels'. Options: modes, band_hz [lo, hi], shift_hz, method ('auto',
    'sparse', 'dense'), tolerance; a case's analysis: section is the default."""
    if _is_case(model):
        return _dynid._modal_case(model, options)
    return _dynid._modal_model(model, options)


def solve_eigen(K, M, **options):
    """K phi = lambda M phi for matrices a host code already has (SciPy sparse or NumPy): the lowest `modes`
    (default 10) or a band; shift-invert Lanczos on CHOLMOD. Returns 'frequency_hz', 'eigenvalues', 'shapes'."""
    return _dynid._solve_eigen(K, M, options)


def detect(model, measured=None, *, reference_measured=None, simulated_changed=None, **options):
    """Locate and quantify changes by residual forces (the paper's method): the detect results JSON plus
    'residuals' (dofs x modes, eq. 6), 'pseudo', 'delta_pseudo' and 'residual_dofs'.

    detect(case)                           the case's detect: section, as `dynid detect`
    detect(model, measured, **options)     measured modal data (a dict, e.g. from sample_modes or identify)
    detect(model, changed={...}, ...)      a simulation, as the case-file key changed:
    Options are the case file's detect: keys (modes, noise {frequency, shape}, significance, max_changed, refine,
    serep_modes, min_mac, candidates, measured_dofs with changed:). `simulated_changed` (a Model) marks exact
    simulated data (extended-precision residuals)."""
    if _is_case(model):
        _no_options(model, options, "detect")
        return _dynid._detect(model, measured, reference_measured, simulated_changed)
    if measured is not None and "measured" not in options:
        options["measured"] = _PYTHON_SOURCE
    case = _case_for(model, "detect", options, options.pop("name", "python"))
    return _dynid._detect(case, measured, reference_measured, simulated_changed)


def update(model, measured=None, *, parameters=None, **options):
    """FE model updating (Ceres): the update results JSON plus 'theta'.

    update(case)                                     the case's update: section, as `dynid update`
    update(model, measured, parameters=[...], ...)   parameters as the case file's (dicts: name, factor, each,
                                                     elements, group, region, mass, spring, bounds, initial, ...)
    Options are the case file's update: keys (objective, noise, regularization, loss, solver, max_iterations,
    modes, target)."""
    if _is_case(model):
        _no_options(model, options, "update")
        if parameters is not None:
            raise InputError("dynid.update: a case brings its own parameters")
        return _dynid._update(model, measured)
    if parameters is not None:
        options["parameters"] = parameters
    if measured is not None and "measured" not in options:
        options["measured"] = _PYTHON_SOURCE
    case = _case_for(model, "update", options, options.pop("name", "python"))
    return _dynid._update(case, measured)


def discover(model, measured=None, *, recordings=None, **options):
    """Missing-physics discovery: the discover results JSON (verdict, findings, candidates, fit, ...).

    discover(case)                               the case's discover: section, as `dynid discover`
    discover(model, measured, **options)         measured modal data (a dict; identify's result works too)
    discover(model, recordings=[...], **options) recordings (dicts, e.g. simulate_test's), identified first as
                                                 the case's recordings are (options identify {method, band_hz,
                                                 orders}; without a band, identification_band)
    Options are the case file's discover: keys (modes, min_mpc, frequency_noise, shape_noise, kinds,
    sensor_nodes, suspension_nodes, max_effects, units, screen, expect, ...)."""
    if _is_case(model):
        _no_options(model, options, "discover")
        return _dynid._discover(model, measured, recordings)
    if measured is not None and recordings is not None:
        raise InputError("dynid.discover: give measured modal data or recordings, not both")
    if measured is not None:
        options.setdefault("measured", _PYTHON_SOURCE)
    elif recordings is not None:
        options.setdefault("recordings", [_PYTHON_SOURCE])
    case = _case_for(model, "discover", options, options.pop("name", "python"))
    return _dynid._discover(case, measured, recordings)


def simulate_test(model, seed_offset=0, **options):
    """A virtual vibration test of a Model (options: the case file's test: keys, e.g. sensors, excitation,
    inputs, sample_rate_hz, duration_s, impacts, noise, seed) or of a Case's test: section. Returns
    {'recordings': [recording dicts: sample_rate_hz, channels, records (samples x channels arrays)],
    'truth': the simulated modes at the sensors, 'identify': the test's identification options}. No file is
    written."""
    if _is_case(model):
        _no_options(model, options, "test")
        return _dynid._simulate_test(model, seed_offset)
    case = _case_for(model, "test", options, options.pop("name", "python"))
    return _dynid._simulate_test(case, seed_offset)


def identify(recordings=None, *, frf=None, **options):
    """Modal identification: LSCF + LSFD (FRFs, or recordings with a force channel) or SSI-cov (output-only).

    recordings: a recording dict or a list of them (a roving hammer: one per hit location), or frf=: FRF dicts.
    Options: method ('lscf' | 'ssi'; default by the data), band_hz [lo, hi], orders [min, max], and the
    stabilization settings of IdentificationOptions (stable_frequency, stable_damping, stable_mac, max_damping,
    min_cluster_fraction, cluster_tolerance, cluster_damping, order_step, block_rows, decimate).
    Returns the identify results JSON (method, dofs, orders, modes) plus 'modal_data' (arrays) and
    'stabilization' (poles: order, frequency, damping; the spectrum behind)."""
    if (recordings is None) == (frf is None):
        raise InputError("dynid.identify: give recordings or frf")
    return _dynid._identify(recordings, frf, options)


def estimate_frf(recordings, **options):
    """H1/H2 FRFs of recordings with force channels (options: estimator, segment, overlap, force_window,
    exponential_end, max_frequency_hz)."""
    return _dynid.estimate_frf(recordings, options)


def read_mat_recording(path, **names):
    """A recording from a .mat file: data (channels x samples, default variable 'data'), sample_rate (variable,
    default 'fs') or sample_rate_hz (a number), channels (variable of DOF labels, default 'channels') or
    channel_labels (a list), inputs (labels of force channels), quantity of the others."""
    return _dynid.read_mat_recording(path, names)


def read_mat_modal_data(path, **names):
    """Modal data from a .mat file: frequency_hz (or eigenvalues in (rad/s)^2), shapes (DOFs x modes), dofs
    (labels or [node, dof 1..6] rows), damping (optional) - each the name of a variable."""
    return _dynid.read_mat_modal_data(path, names)
