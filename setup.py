"""Packaging hook: the wheel ships the firmware and protocol C sources the simulated boards build
from (host/emulator/_sources), copied at build time from the checkout (or the sdist)."""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
SHIPPED = ("firmware/atmega328", "protocol/c")  # what build.py and core.py compile
SKIP = shutil.ignore_patterns("build", "*.o", "*.elf", "*.hex", "__pycache__")


class BuildWithSources(build_py):
    """build_py that also copies the C sources into the built package."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):  # an editable install reads the checkout
            return
        target = Path(self.build_lib) / "host" / "emulator" / "_sources"
        for rel in SHIPPED:
            src = HERE / rel
            if not src.is_dir():
                raise SystemExit(f"setup.py: {src} missing: build from a checkout or the sdist")
            shutil.copytree(src, target / rel, ignore=SKIP, dirs_exist_ok=True)


setup(cmdclass={"build_py": BuildWithSources})
