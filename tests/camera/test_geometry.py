"""The Minoru's nominal geometry comes from one module, says nothing itself, and the calibration
modules import one way only."""

import subprocess
import sys
from argparse import Namespace

from host.camera.geometry import MINORU_BASELINE_M, MINORU_FOCAL_PX_320, Geometry
from host.camera.open import source_geometry


def test_minoru_default_scales_the_focal_length_and_prints_nothing(capsys):
    g = Geometry.minoru_default(640, 480)
    assert (g.focal_px, g.baseline_m, g.cx, g.cy) == (2 * MINORU_FOCAL_PX_320,
                                                       MINORU_BASELINE_M, 320.0, 240.0)
    assert capsys.readouterr() == ("", "")


def test_without_calib_the_command_says_it_assumes_the_minoru(capsys):
    g = source_geometry(Namespace(calib=None, size="320x240"))
    assert g == Geometry.minoru_default(320, 240)
    assert "no --calib: assuming the Minoru's nominal geometry" in capsys.readouterr().err


def test_calibration_files_do_not_import_the_calibration_fit():
    code = ("import sys, host.camera.calib_files; "
            "sys.exit('host.camera.calibration' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
