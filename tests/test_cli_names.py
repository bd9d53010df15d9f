"""The command's names: --version, the stereo-servo entry point, and a stray host.py in the
working folder named in one line instead of silently run or half-imported."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import host
from host.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_version_names_the_package_and_its_version(capsys) -> None:
    try:
        main(["--version"])
    except SystemExit as e:
        assert e.code == 0
    assert capsys.readouterr().out == f"stereo-servo {host.__version__}\n"


def _entry(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "stereo_servo", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=120)


def test_a_stray_host_py_is_named_not_run(tmp_path: Path) -> None:
    (tmp_path / "host.py").write_text("print('the stray file ran')\n")
    r = _entry(tmp_path, "--version")
    assert r.returncode == 2 and "ran" not in r.stdout
    assert r.stderr.count("\n") == 1
    assert f"{tmp_path / 'host.py'} shadows the stereo-servo package" in r.stderr


def test_the_entry_point_runs_the_cli_when_nothing_shadows_it(tmp_path: Path) -> None:
    r = _entry(tmp_path, "--version")
    assert (r.returncode, r.stdout) == (0, f"stereo-servo {host.__version__}\n"), r.stderr


# Ctrl-C delivered for real (os.kill) at a chosen import while `host eval` loads its libraries,
# instead of after a guessed delay: 0.3 s of sleep at load 9 landed in the interpreter's own
# start (exit -2, before any of our code runs). At "datetime" it lands inside numpy's C import
# (PyCapsule_Import), which turned the KeyboardInterrupt into an ImportError.
SIGINT_AT = r"""
import os, signal, sys
at = sys.argv.pop(1)
class SigintAt:
    def find_spec(self, name, path=None, target=None):
        if name == at and "numpy" in sys.modules:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.SIGINT)
sys.meta_path.insert(0, SigintAt())
sys.argv[0] = "host"
import stereo_servo
sys.exit(stereo_servo.main())
"""


@pytest.mark.parametrize("at", ["datetime", "numpy.linalg", "cv2", "numba"])
def test_ctrl_c_while_the_libraries_load_is_one_line_and_130(tmp_path: Path, at: str) -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", SIGINT_AT, at, "eval"], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=120)
    assert (r.returncode, r.stderr) == (130, "host: interrupted\n")
