"""Work–precision chart and stability study of every method (thin wrapper of the CLI).

    python benchmarks/work_precision.py [--quick] [--out DIR] [--cases 1,2,3] [--methods ...]

Same as `nonsmooth-rod benchmark`; writes work_precision.png/.csv, stability.md/.csv and
bistable_map.csv into DIR (default ./benchmark). Full: about 4 minutes on 2 cores; --quick: ~10 s.
The conclusions are in docs/speed-accuracy.md.
"""
from __future__ import annotations

import sys

from nonsmooth_rod.cli import main

if __name__ == "__main__":
    sys.exit(main(["benchmark", *sys.argv[1:]]))
