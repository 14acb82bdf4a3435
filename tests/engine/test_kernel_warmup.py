"""`engine.kernel_warmup`: after it, the first evaluation imports no numba tables."""

import json
import math
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

_SCRIPT = """
import json, sys
sys.path.insert(0, {root!r})
from engine.kernel_warmup import warm_up_kernels
value = warm_up_kernels()
loaded = {{m for m in sys.modules if m.startswith(("numba.cpython", "numba.np", "skimage.measure"))}}
from app.evaluation import evaluate_document
from engine.graph import load_project
before = set(sys.modules)
report = evaluate_document(load_project({example!r}))
late = sorted(m for m in set(sys.modules) - before if m.startswith(("numba.cpython", "numba.core.typing")))
print(json.dumps({{"value": value, "loaded": len(loaded), "late": late, "ok": report.ok}}))
"""


def test_warm_up_loads_what_the_first_evaluation_would():
    example = str(ROOT / "resources" / "examples" / "octet.json")
    out = subprocess.run([sys.executable, "-c", _SCRIPT.format(root=str(ROOT), example=example)],
                         capture_output=True, text=True, timeout=600, check=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert math.isclose(got["value"], sum(math.sqrt(k) for k in range(4)), rel_tol=1e-12)
    assert got["ok"]
    assert got["loaded"] > 20            # numba's implementation tables and marching cubes are in
    assert got["late"] == []             # the evaluation itself imported none of them
