"""bench/servo.py --stages wraps what the loop calls by name: every name must still be there
(f63a2c9 moved Servo._robot_disparity to loop.marker_disparity and --stages failed with an
AttributeError at its start)."""

import importlib.util
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent.parent / "bench" / "servo.py"


def _stages() -> dict[str, tuple[object, str]]:
    spec = importlib.util.spec_from_file_location("bench_servo", BENCH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.STAGES  # type: ignore[no-any-return]


@pytest.mark.parametrize("name", list(_stages()))
def test_each_stage_the_bench_times_is_still_called_by_that_name(name: str) -> None:
    owner, attr = _stages()[name]
    assert callable(getattr(owner, attr, None)), f"{name}: {owner!r} has no {attr}"
