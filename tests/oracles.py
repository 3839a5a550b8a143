"""Where the tests find the oracles nobody here wrote.

check_urdf (urdfdom) comes with the `pin` wheel, beside the Python running the tests;
never a path of one particular machine.
"""

import shutil
import sys
from pathlib import Path

_BESIDE_PYTHON = Path(sys.executable).parent / "check_urdf"
CHECK_URDF = str(_BESIDE_PYTHON) if _BESIDE_PYTHON.exists() else (shutil.which("check_urdf")
                                                                    or "check_urdf")
