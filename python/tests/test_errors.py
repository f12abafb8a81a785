"""Engine errors arrive as Python exceptions with the command line's messages."""
import pathlib

import numpy as np
import pytest

import dynid
from conftest import ROOT

BAD = ROOT / "tests" / "data" / "bad"


@pytest.mark.parametrize("name", ["unknown-element-type.yaml", "missing-node.yaml", "zero-section.yaml", "unsupported.yaml",
                                  "malformed.yaml", "bad-detect.yaml", "bad-update.yaml"])
def test_case_errors_have_the_cli_message(cli, name):
    r = cli("modal", BAD / name, check=False)
    assert r.returncode == 2
    cli_message = r.stderr.strip().split("error: ", 1)[1]
    with pytest.raises(dynid.InputError) as e:
        c = dynid.load_case(BAD / name)
        dynid.modal(c)
    assert str(e.value) == cli_message
    assert isinstance(e.value, ValueError)  # bad input is a ValueError to generic Python code


def test_exception_hierarchy():
    assert issubclass(dynid.InputError, ValueError)
    assert issubclass(dynid.NumericalError, ArithmeticError)
    assert issubclass(dynid.InternalError, RuntimeError)


def test_bad_arguments_are_named(paper_frame):
    with pytest.raises(dynid.InputError, match=r"dynid.modal: unknown option 'mode'"):
        dynid.modal(paper_frame, mode=3)
    with pytest.raises(dynid.InputError, match=r"unknown key 'modez' in detect"):
        dynid.detect(paper_frame, {"dofs": ["5ux"], "frequency_hz": [1.0], "shapes": [[1.0]]}, modez=3)
    with pytest.raises(dynid.InputError, match=r"'frequency_hz' is missing"):
        dynid.detect(paper_frame, {"dofs": ["5ux"], "shapes": [[1.0]]})
    with pytest.raises(dynid.InputError, match=r"node 99 is not in the model"):
        dynid.detect(paper_frame, {"dofs": ["99ux"], "frequency_hz": [1.0], "shapes": [[1.0]]})
    with pytest.raises(dynid.InputError, match=r"'13xx' is not a DOF label"):
        paper_frame.equations(["13xx"])
    with pytest.raises(dynid.InputError, match=r"modes must be >= 1"):
        dynid.modal(paper_frame, modes=0)
    with pytest.raises(dynid.InputError, match=r"residual_forces: 2 eigenvalues for 3 shapes"):
        dynid.residual_forces(np.eye(4), np.eye(4), np.ones(2), np.ones((4, 3)))
    with pytest.raises(dynid.InputError, match=r"a 3 x 4 matrix; a square one is needed"):
        dynid.solve_eigen(np.ones((3, 4)), np.ones((3, 4)))
    with pytest.raises(dynid.InputError, match=r"tie: parameter 'rho:44' does not exist"):
        dynid.update(paper_frame, {"dofs": ["5ux"], "frequency_hz": [1.0], "shapes": [[1.0]]},
                     parameters=[{"name": "rho", "factor": "rho", "each": "all"},
                                 {"name": "x", "factor": "rho", "elements": [7], "tie": {"to": "rho:44", "ratio": 1.0}}])
    with pytest.raises(dynid.InputError, match="give recordings or frf"):
        dynid.identify()
    with pytest.raises(dynid.InputError, match=r"'sample_rate_hz' is missing"):
        dynid.identify([{"channels": ["1ux"], "records": [np.zeros((10, 1))]}])


def test_options_do_not_mix_with_a_case(cases):
    with pytest.raises(dynid.InputError, match="a case brings its own detect: section"):
        dynid.detect(dynid.load_case(cases / "paper-frame-damage" / "element9-case1.yaml"), modes=3)
    with pytest.raises(dynid.InputError, match="has no detect: section"):
        dynid.detect(dynid.load_case(cases / "paper-frame"))
