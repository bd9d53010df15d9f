"""`host ...` run in the test's own process, as a subprocess's result: exit status, stdout and
stderr (no Python start-up and import per call, the same one-line errors and exit statuses)."""

from __future__ import annotations

import contextlib
import io
import subprocess

from host.cli import main


def host(*argv: str) -> subprocess.CompletedProcess[str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(list(argv))
        except SystemExit as e:  # argparse's refusal
            code = int(e.code or 0)
    return subprocess.CompletedProcess(["host", *argv], code, out.getvalue(), err.getvalue())
