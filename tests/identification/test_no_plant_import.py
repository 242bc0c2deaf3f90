"""The identification library works on anyone's data: it never imports hwpts.plant (DESIGN.md 1)."""

import subprocess
import sys


def test_identification_does_not_import_plant():
    code = (
        "import sys, hwpts.identification, hwpts.identification.pwarx, hwpts.io.models, "
        "hwpts.identification.segmentation, hwpts.identification.synthetic, hwpts.identification.polish;"
        "bad = [m for m in sys.modules if m == 'hwpts.plant' or m.startswith('hwpts.plant.')];"
        "print(bad); sys.exit(1 if bad else 0)"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
