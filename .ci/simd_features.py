"""Print the numpy SIMD dispatch targets this CPU runs beyond numpy's baseline.

`.ci/run` passes them to NPY_DISABLE_CPU_FEATURES for a second pytest run, so the suite
also runs on the baseline kernels a CPU without AVX2/AVX-512 would use. Computed here,
from numpy itself, because the names differ across numpy versions (AVX512F, AVX512_SKX,
AVX2 ... before 2.4; X86_V3, X86_V4, AVX512_ICL ... since) and disabling a baseline
feature is an error. `--check NAMES` instead exits 1 unless every one of NAMES is off
in this process (run it under the variable: the restriction really took).
"""

from __future__ import annotations

import sys

try:
    from numpy._core._multiarray_umath import (
        __cpu_baseline__, __cpu_dispatch__, __cpu_features__)
except ImportError:         # numpy < 2.0
    from numpy.core._multiarray_umath import (
        __cpu_baseline__, __cpu_dispatch__, __cpu_features__)


def dispatched_on_this_cpu() -> list[str]:
    return [name for name in __cpu_dispatch__
            if __cpu_features__.get(name) and name not in __cpu_baseline__]


if __name__ == "__main__":
    if sys.argv[1:2] == ["--check"]:
        still_on = [name for name in sys.argv[2:] if __cpu_features__.get(name)]
        if still_on:
            sys.exit(f"NPY_DISABLE_CPU_FEATURES did not take: {' '.join(still_on)} still on")
        print("numpy dispatch now: baseline", " ".join(__cpu_baseline__), "+",
              " ".join(dispatched_on_this_cpu()) or "nothing")
    else:
        print(" ".join(dispatched_on_this_cpu()))
