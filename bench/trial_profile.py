"""Where a faulty trial's CPU goes (host servo --sim --trials, 320x240, one thread): the trials
run in this process with the big pieces timed (process CPU time, each piece without the pieces
it calls), after their cameras' calibrations and a first trial (the core's library, numba's
cache) so that neither is counted.

    python bench/trial_profile.py --seed 3 --trials 0 1 2 3 4 5
    python bench/trial_profile.py --plain   # the trials' CPU alone, nothing timed inside

--plain times each trial whole, without the wrappers (which cost some CPU of their own); with
PYTHONPATH pointing at another checkout it times that code with the same script, which is how
a before/after ratio is taken (run them alternately: the machine is shared). With --plain,
--colour-camera runs each trial a second time, right after, with the simulated camera sending
its colour images as a real Minoru does (the trials' camera renders them in grey, since the
servo matches in grey: host.sim.run, Renderer's grey), and prints the two CPU times side by
side and their ratio. With --plain, --against DIR (another checkout, e.g. `git worktree add` or
`git archive` of the commit before) loads that checkout's `host` too, in this same process
(each version's modules swapped into sys.modules while it runs), and runs each trial with
both, alternating which goes first: the CPU a trial of this code against that code's, their
ratio, and whether the two gave the same trial records (exit 1 if not). Dev seeds only (1..8,
100..199; never 9 or 10..99, the lead's reported campaigns). Prints the load average with the
figures."""

from __future__ import annotations

import argparse
import collections
import contextlib
import os
import sys
import time
from collections.abc import Callable, Iterator
from typing import Any

from host.sim.trial_backends import one_thread

DEV_SEEDS = (*range(1, 9), *range(100, 200))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--trials", type=int, nargs="+", default=[0, 1, 2, 3, 4, 5])
    ap.add_argument("--plain", action="store_true",
                    help="time whole trials only (no wrappers inside)")
    ap.add_argument("--colour-camera", action="store_true",
                    help="each trial again with the camera sending colour images (the "
                         "reference for the grey camera's ratio)")
    ap.add_argument("--against", metavar="DIR",
                    help="another checkout: each trial also with its code, alternating")
    a = ap.parse_args()
    if (a.colour_camera or a.against) and not a.plain:
        ap.error("--colour-camera and --against go with --plain (whole trials timed, "
                 "alternating)")
    if a.seed not in DEV_SEEDS:
        ap.error("dev seeds only: 1..8 and 100..199 (9 and 10..99 are held out for reported "
                 "figures)")
    one_thread()
    if a.against:
        raise SystemExit(_against(a.against, a.seed, a.trials))
    import host.camera.calibration as calibration
    import host.emulator.emulator as emulator
    import host.link.client as client
    import host.servo.loop as loop
    import host.servo.perception as perception
    import host.sim.renderer as renderer
    import host.sim.source as source
    import host.sim.world as world
    from host.sim.run import _calibration
    from host.sim.trials import run_trial, trial_setup
    from host.stereo.params import MatcherParams

    spent: collections.Counter[str] = collections.Counter()
    calls: collections.Counter[str] = collections.Counter()
    stack: list[float] = []

    def timed(owner: object, name: str, label: str) -> None:
        f: Callable = getattr(owner, name)

        def wrapper(*args, **kw):
            t0 = time.process_time()
            stack.append(0.0)
            try:
                return f(*args, **kw)
            finally:
                dt = time.process_time() - t0
                spent[label] += dt - stack.pop()
                calls[label] += 1
                if stack:
                    stack[-1] += dt
        setattr(owner, name, wrapper)

    if a.plain:
        timed = _untimed
    timed(renderer.Renderer, "view", "render a view")
    timed(loop, "marker_candidates", "marker search")
    timed(world.World, "step", "world 1 ms step")
    timed(emulator.Emulator, "advance", "emulator advance")
    timed(source.SimSource, "run_ms", "lockstep run_ms loop")
    timed(loop, "compute_disparity", "disparity (servo loop)")
    timed(perception, "compute_disparity", "disparity (perception)")
    timed(calibration.Rectifier, "__call__", "rectify a pair")
    timed(loop, "match_exposure", "match exposure")
    timed(client.RobotLink, "_transact", "link transaction")
    timed(loop, "match_window", "lane window match")
    timed(loop, "lane_obstacle", "lane obstacle")
    timed(loop, "floor_shift_px", "floor shift")
    timed(loop, "camera_moved", "floor shift")
    timed(loop, "deflickered", "deflicker")
    timed(loop, "block_disparity", "marker ring disparity")
    timed(loop.Servo, "step", "servo step (the rest)")
    params = MatcherParams.for_matcher(MatcherParams.matcher).validate()
    size = (320, 240)
    for i in a.trials:
        s = trial_setup(a.seed, i, size, params, False)
        _calibration(size, s.faults.camera.distortion, s.calib_seed)
    run_trial((a.seed, a.trials[0], size, params, False))
    spent.clear()
    calls.clear()
    load = os.getloadavg()[0]
    t0 = time.process_time()
    sim = 0.0
    colour_cpu = 0.0
    for i in a.trials:
        t1 = time.process_time()
        t = run_trial((a.seed, i, size, params, False))
        cpu = time.process_time() - t1
        sim += t.sim_s
        print(f"trial {i}: {cpu:.2f} s CPU, {t.sim_s:.1f} s simulated, "
              f"{t.outcome} {t.reason} [{t.faults}]")
        if a.colour_camera:
            t2 = time.process_time()
            with _colour_camera(renderer):
                c = run_trial((a.seed, i, size, params, False))
            colour_cpu += time.process_time() - t2
            print(f"   colour camera: {time.process_time() - t2:.2f} s CPU, {c.sim_s:.1f} s "
                  f"simulated, {c.outcome} {c.reason}")
    total = time.process_time() - t0 - colour_cpu
    if a.colour_camera:
        print(f"grey camera {total:.2f} s CPU, colour camera {colour_cpu:.2f} s: "
              f"{total / colour_cpu:.2f}x (alternating in this process)")
    steps = calls["servo step (the rest)"]
    frames = f"; {steps} frames processed, {1e3 * total / max(1, steps):.2f} ms a frame" \
        if steps else ""
    print(f"load {load:.1f} -> {os.getloadavg()[0]:.1f}; {total:.2f} s CPU for {sim:.1f} s "
          f"simulated: {15 * total / sim:.2f} s per 15 s{frames}")
    for label, v in spent.most_common():
        print(f"  {label:24s} {v:6.2f} s {100 * v / total:5.1f} %  {calls[label]:7d} calls "
              f"{1e3 * v / max(1, calls[label]):7.3f} ms each")
    print(f"  {'other':24s} {total - sum(spent.values()):6.2f} s")


@contextlib.contextmanager
def _colour_camera(renderer: Any) -> Iterator[None]:
    """The simulated camera sends its colour images (the Renderer's grey off) meanwhile."""
    init = renderer.Renderer.__init__

    def colour(self: Any, *args: Any, **kw: Any) -> None:
        init(self, *args, **(kw | {"grey": False}))

    renderer.Renderer.__init__ = colour
    try:
        yield
    finally:
        renderer.Renderer.__init__ = init


def _host_modules() -> dict[str, Any]:
    return {k: m for k, m in sys.modules.items() if k == "host" or k.startswith("host.")}


@contextlib.contextmanager
def _modules(mods: dict[str, Any]) -> Iterator[None]:
    """One version's `host` modules in sys.modules meanwhile (its functions' late imports
    find their own version's)."""
    saved = _host_modules()
    for k in saved:
        del sys.modules[k]
    sys.modules.update(mods)
    try:
        yield
    finally:
        for k in _host_modules():
            del sys.modules[k]
        sys.modules.update(saved)


def _version(path: str | None) -> tuple[dict[str, Any], Callable[..., Any]]:
    """The `host` modules of the checkout at path (None: this one, as PYTHONPATH gives it),
    imported afresh, and a run of one trial with them (calibrations and a first trial done)."""
    with _modules({}):
        if path:
            sys.path.insert(0, path)
        try:
            from host.sim.run import _calibration
            from host.sim.trials import run_trial, trial_setup
            from host.stereo.params import MatcherParams
        finally:
            if path:
                sys.path.remove(path)
        mods = _host_modules()
    params = MatcherParams.for_matcher(MatcherParams.matcher).validate()

    def run(seed: int, i: int, warm: bool = False) -> Any:
        with _modules(mods):
            if warm:
                s = trial_setup(seed, i, (320, 240), params, False)
                _calibration((320, 240), s.faults.camera.distortion, s.calib_seed)
                return None
            return run_trial((seed, i, (320, 240), params, False))
    return mods, run


def _record(t: Any) -> str:
    """A trial's record as the campaign's JSON writes it (the same dataclass fields)."""
    import dataclasses
    import json
    return json.dumps(dataclasses.asdict(t), sort_keys=True, default=str)


def _against(other: str, seed: int, trials: list[int]) -> int:
    """This checkout's trials against `other`'s, alternating in this process."""
    _, new = _version(None)
    old_mods, old = _version(os.path.abspath(other))
    print(f"this code: {sys.modules['host'].__file__}; against: "
          f"{old_mods['host'].__file__}")
    for i in trials:
        new(seed, i, warm=True)
        old(seed, i, warm=True)
    new(seed, trials[0])
    old(seed, trials[0])
    load = os.getloadavg()
    cpu = {"new": 0.0, "old": 0.0}
    differ = []
    for n, i in enumerate(trials):
        got = {}
        for name in (("new", "old") if n % 2 == 0 else ("old", "new")):
            t0 = time.process_time()
            got[name] = (new if name == "new" else old)(seed, i)
            cpu[name] += time.process_time() - t0
        same = _record(got["new"]) == _record(got["old"])
        if not same:
            differ.append(i)
        print(f"trial {i}: {got['new'].outcome:8s} new/old so far "
              f"{cpu['new'] / cpu['old']:.3f}{'' if same else '  RECORDS DIFFER'}", flush=True)
    print(f"load {load[0]:.1f}/{load[1]:.1f}/{load[2]:.1f} -> "
          f"{'/'.join(f'{v:.1f}' for v in os.getloadavg())}; seed {seed}, {len(trials)} "
          f"trials: this code {cpu['new']:.2f} s CPU ({cpu['new'] / len(trials):.3f} a trial), "
          f"{other} {cpu['old']:.2f} s ({cpu['old'] / len(trials):.3f}): "
          f"{cpu['new'] / cpu['old']:.3f}x; records "
          f"{'identical' if not differ else 'differ in trials ' + str(differ)}")
    return 1 if differ else 0


def _untimed(owner: object, name: str, label: str) -> None:
    """--plain: leave the function as it is."""


if __name__ == "__main__":
    main()
