"""pip install gives every command: the sdist and the wheel built from it, installed into a fresh
venv outside the checkout, run the simulated servo and the emulators from there."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _run(args: list, cwd: Path, env: dict | None = None, timeout: float = 600):
    return subprocess.run([str(a) for a in args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=timeout)


def _checkout_copy(dest: Path) -> Path:
    """The files git would commit (tracked, or new and not ignored): no build outputs."""
    files = _run(["git", "-C", ROOT, "ls-files", "-z", "--cached", "--others",
                  "--exclude-standard"], ROOT).stdout.split("\0")
    for rel in filter(None, files):
        if (ROOT / rel).is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / rel, dest / rel)
    return dest


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> tuple[Path, dict]:
    """The wheel (built from the sdist) installed into a new venv that borrows the running
    interpreter's packages for the dependencies (so no download but the build backend's)."""
    if shutil.which("git") is None:
        pytest.skip("git not found")
    tmp = tmp_path_factory.mktemp("wheel")
    src = _checkout_copy(tmp / "src")
    r = _run([sys.executable, "setup.py", "-q", "sdist", "-d", tmp / "dist"], src)
    assert r.returncode == 0, r.stderr[-2000:]
    sdist = next((tmp / "dist").glob("stereo[-_]servo-*.tar.gz"))
    r = _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", tmp / "wheel",
              sdist], tmp)
    assert r.returncode == 0, r.stderr[-2000:]
    wheel = next((tmp / "wheel").glob("stereo_servo-*.whl"))
    env_dir = tmp / "venv"
    venv.create(env_dir, with_pip=False)
    py = env_dir / "bin" / "python"
    site = Path(_run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                     tmp).stdout.strip())
    (site / "borrowed.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    r = _run([sys.executable, "-m", "pip", "--python", py, "install", "-q", "--no-deps",
              "--force-reinstall", "--no-index", wheel], tmp)
    assert r.returncode == 0, r.stderr[-2000:]
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env |= {"XDG_CACHE_HOME": str(tmp / "cache"), "PATH": f"{env_dir / 'bin'}:{env['PATH']}"}
    work = tmp / "work"
    work.mkdir()
    return work, env


@pytest.mark.slow
def test_the_installed_package_is_the_one_that_runs(installed) -> None:
    work, env = installed
    r = _run(["python", "-c", "import host; print(host.__file__)"], work, env)
    assert str(work.parent / "venv") in r.stdout, r.stdout + r.stderr


@pytest.mark.slow
def test_servo_sim_runs_from_the_installed_wheel(installed) -> None:
    work, env = installed
    r = _run(["host", "servo", "--sim", "--duration", "1"], work, env)
    assert r.returncode == 0, r.stderr[-2000:]
    assert "target: nearest object" in r.stderr
    assert list((work.parent / "cache" / "stereo-servo").glob("firmware-core-*.so"))


@pytest.mark.slow
def test_emulate_runs_from_the_installed_wheel(installed) -> None:
    work, env = installed
    r = _run(["stereo-servo", "emulate", "--duration", "1"], work, env)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.startswith("/dev/pts/"), r.stdout


@pytest.mark.slow
@pytest.mark.parametrize("board", ["--simavr", "--uno"])
def test_the_simavr_boards_build_from_the_shipped_sources(installed, board: str) -> None:
    need = {"--simavr": ["avr-gcc", "make"], "--uno": []}[board]
    missing = [t for t in ["gcc", *need] if shutil.which(t) is None]
    if missing or not Path("/usr/include/simavr/sim_avr.h").exists():
        pytest.skip(f"not installed: {missing or 'simavr headers'}")
    if board == "--uno" and not Path("/usr/share/arduino/hardware/arduino/avr/bootloaders/"
                                     "optiboot/optiboot_atmega328.hex").exists():
        pytest.skip("the Uno's bootloader (arduino-core-avr) is not installed")
    work, env = installed
    r = _run(["host", "emulate", board, "--duration", "1"], work, env)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.startswith("/dev/pts/"), r.stdout
    cache = work.parent / "cache" / "stereo-servo"
    assert list((cache / "simavr").iterdir())
    if board == "--simavr":  # make ran in a copy of the shipped sources, not in the package
        assert list(cache.glob("firmware-src-*/firmware/atmega328/build/firmware.elf"))
