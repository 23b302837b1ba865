"""Writing and reading the posteriors' NetCDF files: xarray's netCDF4 engine (netCDF-C, what
bayesfo uses) against h5netcdf (h5py), where that is installed, in the same process,
alternating, so that the load touches both alike.

What is timed is what ``bayesfo compare`` and ``bayesfo.load`` do per structure: the DataTree of
a posterior as its NetCDF stores it (``netcdf_for``) written to memory and then to a file
(:func:`bayesfo.inference.results.save_netcdf`'s way), and a file read back into memory
(:func:`bayesfo.inference._arviz.open_tree`'s way). Data: the bundled adhesive isotherm at 20 °C,
the default structures (seven posteriors, 2 000–4 000 draws each). Every file read back is
checked to be identical (``DataTree.identical``) to what was written, whichever engine reads it.

Prints the median over ``--repeat`` rounds of the seconds per file, per engine.

Usage: python benchmarks/bench_netcdf.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import statistics
import tempfile
import time
import warnings
from pathlib import Path

import bayesfo as bf
from bayesfo.comparison.stored import netcdf_for
from bayesfo.options import DEFAULT_STRUCTURES

DATA = Path(__file__).resolve().parents[1] / "examples/data/adhesive_468mp/Tp020C.csv"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    import xarray as xr

    engines = [e for e, module in (("netcdf4", "netCDF4"), ("h5netcdf", "h5netcdf"))
               if importlib.util.find_spec(module) is not None]
    comparison = bf.compare(bf.read(DATA), DEFAULT_STRUCTURES, workers=1, seed=0,
                            progress=False)
    trees = [netcdf_for(comparison, r) for r in comparison.results if r.posterior is not None]
    print(f"machine: {platform.machine()}, python {platform.python_version()}, xarray "
          f"{xr.__version__}; {len(trees)} posteriors; load {os.getloadavg()[0]:.2f}")
    write = {e: [] for e in engines}
    read = {e: [] for e in engines}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.repeat):
            for engine in engines:
                t = time.perf_counter()
                for i, tree in enumerate(trees):
                    data = tree.to_netcdf(engine=engine)
                    Path(tmp, f"{engine}{i}.nc").write_bytes(data)
                write[engine].append((time.perf_counter() - t) / len(trees))
                t = time.perf_counter()
                for i in range(len(trees)):
                    with xr.open_datatree(Path(tmp, f"{engine}{i}.nc"), engine=engine) as tree:
                        tree.load()
                read[engine].append((time.perf_counter() - t) / len(trees))
        for writer in engines:
            for reader in engines:
                for i, tree in enumerate(trees):
                    with xr.open_datatree(Path(tmp, f"{writer}{i}.nc"), engine=reader) as back:
                        if not back.load().identical(tree):
                            raise SystemExit(f"{writer} → {reader}: posterior {i} differs")
    print(f"{'engine':<10} {'write [s/file]':>15} {'read [s/file]':>14}")
    for engine in engines:
        print(f"{engine:<10} {statistics.median(write[engine]):15.3f} "
              f"{statistics.median(read[engine]):14.3f}")
    print(f"every file identical to its posterior, written and read by {' and '.join(engines)}; "
          f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
