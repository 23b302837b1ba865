"""A NetCDF write that runs out of room mid-file raises OSError instead of crashing the process.

HDF5 writing into a file system that fills up under it (another run took the space after the
free-space check) died with a segmentation fault inside h5py (the file is now built in memory,
by netCDF-C, and written with plain writes). The file size limit of the
process (RLIMIT_FSIZE, with SIGXFSZ ignored) makes the same failure happen at a chosen size
on any POSIX machine: a write beyond it fails with EFBIG, as one on a full disk fails with
ENOSPC.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

pytest.importorskip("resource")

SCRIPT = textwrap.dedent("""
    import os, resource, signal, sys
    import numpy as np
    from bayesfo.inference import save_netcdf
    from bayesfo.inference._arviz import from_dict

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    tree = from_dict({"posterior": {"a": np.random.default_rng(0).normal(size=(4, 40000))}})
    resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, resource.RLIM_INFINITY))
    try:
        save_netcdf(tree, sys.argv[1])
    except OSError as exc:
        print("OSError", exc.errno, sorted(os.listdir(os.path.dirname(sys.argv[1]))))
""")


def test_a_write_that_runs_out_of_room_raises_and_leaves_nothing(tmp_path):
    import errno

    path = tmp_path / "out" / "zener.nc"
    done = subprocess.run([sys.executable, "-c", SCRIPT, str(path)], capture_output=True,
                          text=True, timeout=120)
    # Before: exit -11 (SIGSEGV) in h5py, a half-written temporary file left behind.
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == f"OSError {errno.EFBIG} []"


def test_a_file_written_through_h5netcdf_reads_back_the_same(tmp_path):
    # Earlier versions wrote the posteriors through h5netcdf; netCDF-C reads them now.
    pytest.importorskip("h5netcdf")
    pytest.importorskip("h5py")  # h5netcdf's backend, not a dependency of its own
    import numpy as np

    from bayesfo.inference._arviz import from_dict, open_tree

    rng = np.random.default_rng(0)
    tree = from_dict({"posterior": {"a": rng.normal(size=(4, 50)),
                                    "G": rng.normal(size=(4, 50, 7))},
                      "log_likelihood": {"G": rng.normal(size=(4, 50, 7))},
                      "observed_data": {"omega": np.logspace(-1, 2, 7)}},
                     dims={"G": ["omega"]})
    tree.posterior.attrs["bayesfo_format"] = 3
    tree.to_netcdf(tmp_path / "old.nc", engine="h5netcdf")
    back = open_tree(tmp_path / "old.nc")
    assert back.identical(tree)
    assert back.posterior.attrs["bayesfo_format"] == 3
