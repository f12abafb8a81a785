"""Start-up (issue 18): `import dynid` and a modal analysis load no MPI, PETSc or SLEPc. The distributed backend is
the plugin libdynid_distributed.so, loaded only when the distributed eigen-solve is asked for (docs/distributed.md)."""
import subprocess
import sys

from conftest import ROOT

HEAVY = ("libmpi", "libopen-pal", "libopen-rte", "libpetsc", "libslepc", "libdynid_distributed")


def loaded_libraries(code):
    # A fresh interpreter: the libraries mapped after `code`, by file name.
    maps = subprocess.run([sys.executable, "-c", code + "\nprint(open('/proc/self/maps').read())"], check=True,
                          capture_output=True, text=True).stdout
    return {line.split()[-1].rsplit("/", 1)[-1] for line in maps.splitlines() if ".so" in line}


def test_import_and_modal_load_no_mpi_petsc_or_slepc():
    libs = loaded_libraries(f"import dynid\ndynid.modal(dynid.load_case({str(ROOT / 'cases' / 'paper-frame')!r}))")
    assert any(name.startswith("_dynid") for name in libs)  # the check sees the module itself
    heavy = sorted(name for name in libs if name.startswith(HEAVY))
    assert heavy == [], f"import dynid and modal() loaded {heavy}"
