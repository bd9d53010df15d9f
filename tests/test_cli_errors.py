"""Bad input to any command: exit status 2, one line on stderr naming the problem, no
traceback, and no file written (outputs are checked before any work). Also: names made from
data stay inside the folder given, outputs keep the umask's mode, all-or-nothing writes."""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import tempfile
import threading
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.cli import main
from host.errors import HostError, describe
from host.files import all_or_nothing, write_text_atomic
from host.stereo.synthetic import synthetic_scene


def _writable(folder: Path) -> bool:
    try:
        fd, name = tempfile.mkstemp(dir=folder)
    except OSError:
        return False
    os.close(fd)
    os.unlink(name)
    return True


@pytest.fixture()
def ro(tmp_path: Path) -> Iterator[Path]:
    """A folder no file can be made in, even by root: mode 0555, else the immutable flag,
    else sysfs (where root cannot make files either)."""
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o555)
    immutable = False
    if _writable(d) and shutil.which("chattr"):  # root ignores the mode
        immutable = subprocess.run(["chattr", "+i", str(d)], capture_output=True).returncode == 0
    if _writable(d):
        d = Path("/sys/kernel")
    assert not _writable(d), "found no folder that cannot be written to"
    yield d
    if immutable:
        subprocess.run(["chattr", "-i", str(tmp_path / "ro")], check=True)
    (tmp_path / "ro").chmod(0o755)


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Inputs good and bad, all in one folder (made once for the file: a test checks that the
    folder is left as it was)."""
    tmp_path = tmp_path_factory.mktemp("inputs")
    s = synthetic_scene(seed=5, width=160, height=120, max_disp=24)
    f = {name.split(".")[0]: tmp_path / name for name in (
        "l.png", "r.png", "colour.png", "small.png", "junk.png", "utf16.toml", "big.toml",
        "deep.toml", "notable.toml", "nan.toml", "unknown.toml", "replay")}
    cv2.imwrite(str(f["l"]), s.left)
    cv2.imwrite(str(f["r"]), s.right)
    grey = s.left if s.left.ndim == 2 else cv2.cvtColor(s.left, cv2.COLOR_BGR2GRAY)
    cv2.imwrite(str(f["l"]), grey)
    cv2.imwrite(str(f["colour"]), cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR))
    cv2.imwrite(str(f["small"]), np.zeros((50, 60), np.uint8))
    f["junk"].write_bytes(b"not an image")
    f["utf16"].write_bytes("[matcher]\nblock_size = 7\n".encode("utf-16"))
    f["big"].write_text("[matcher]\nblock_size = " + "9" * 5000 + "\n")
    f["deep"].write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    f["notable"].write_text("matcher = 'sad'\n")
    f["nan"].write_text("[matcher]\nlr_check = nan\n")
    f["unknown"].write_text("[matcher]\nwindow_size = 7\n")
    for name, meta in (("scene_list", [1, 2]), ("scene_zero", {"scale": 0}),
                       ("scene_nan", {"scale": "nan"}),
                       ("scene_top", {"scale": 4, "max_disparity": "abc"})):
        f[name] = _scene(tmp_path / name, meta)
    f["scene_blank"] = _scene(tmp_path / "scene_blank", {"scale": 4}, blank=True)
    f["replay"].mkdir()
    cv2.imwrite(str(f["replay"] / "left_000.png"), grey)
    cv2.imwrite(str(f["replay"] / "right_000.png"), grey)
    f["swapped"] = _swapped_replay(tmp_path / "swapped")
    f["l16"] = tmp_path / "l16.png"
    cv2.imwrite(str(f["l16"]), grey.astype(np.uint16) * 256)
    h, w = grey.shape
    values = np.full((h, w), 10.0, "<f4").tobytes()
    for name, header, body in (("pfm_abc", b"Pf\nabc 5\n-1\n", values),
                               ("pfm_negsize", b"Pf\n-160 120\n-1\n", values),
                               ("pfm_colour", b"PF\n%d %d\n-1\n" % (w, h), values * 3),
                               ("pfm_nan", b"Pf\n%d %d\nnan\n" % (w, h), values),
                               ("pfm_negative", b"Pf\n%d %d\n-1\n" % (w, h),
                                np.full((h, w), -49.0, "<f4").tobytes()),
                               ("pfm_unknown", b"Pf\n%d %d\n-1\n" % (w, h),
                                np.full((h, w), np.inf, "<f4").tobytes())):
        f[name] = _scene_2014(tmp_path / name, grey, header + body)
    f["calib_banana"] = _scene_2014(tmp_path / "calib_banana", grey,
                                    b"Pf\n%d %d\n-1\n" % (w, h) + values, "ndisp=banana\n")
    f["calib_list"] = tmp_path / "list.yml"
    f["calib_list"].write_text("%YAML:1.0\n---\n- 1\n- 2\n")
    f["calib_ocv"] = tmp_path / "calib.yml"
    f["calib_ocv"].write_text("%YAML:1.0\n---\nimage_size: [160, 120]\n")
    f["ros_equi"] = tmp_path / "right.yaml"
    f["ros_equi"].write_text("image_width: 160\nimage_height: 120\ncamera_matrix: {}\n"
                             "distortion_model: equidistant\n")
    return f


def _swapped_replay(folder: Path) -> Path:
    """A replay of the simulated world with its left and right views exchanged."""
    from host.sim.renderer import Renderer
    from host.sim.world import World

    folder.mkdir()
    pair = Renderer(World.for_size(320, 240)).frame(with_robot=True)
    cv2.imwrite(str(folder / "left_000.png"), pair.right)
    cv2.imwrite(str(folder / "right_000.png"), pair.left)
    return folder


def _scene_2014(folder: Path, grey: np.ndarray, pfm: bytes, calib: str | None = None) -> Path:
    """A Middlebury 2014 layout (im0, im1, disp0GT.pfm, calib.txt) with this PFM's bytes."""
    folder.mkdir()
    cv2.imwrite(str(folder / "im0.png"), grey)
    cv2.imwrite(str(folder / "im1.png"), grey)
    (folder / "disp0GT.pfm").write_bytes(pfm)
    if calib is not None:
        (folder / "calib.txt").write_text(calib)
    return folder


def _tree(root: Path) -> dict[str, tuple[int, float]]:
    return {str(p.relative_to(root)): (p.stat().st_size, p.stat().st_mtime)
            for p in root.rglob("*") if p.is_file()}


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    try:
        code = main(argv)
    except SystemExit as e:  # argparse's refusal
        code = int(e.code or 0)
    return code, capsys.readouterr().err


DISP = ["disparity", "{l}", "{r}", "--num-disparities", "32"]
SERVO = ["servo", "--camera", "replay:{replay}", "--port", "emulator"]

# (argv with {name} for an input and {tmp}/{ro} for folders, words the one line must contain)
ROWS = [
    # outputs: read-only folders, unknown formats, missing folders, the first of two outputs
    (DISP + ["-o", "{ro}/x.png"], "--out {ro}/x.png: cannot write in folder"),
    (["eval", "--picture", "{ro}"], "--picture {ro}: cannot write in folder"),
    (["tune", "--plot", "{ro}/x.png"], "--plot {ro}/x.png: cannot write in folder"),
    (SERVO + ["--log", "{ro}/run.csv"], "--log {ro}/run.csv: cannot write in folder"),
    (SERVO + ["--plot", "{ro}/run.png"], "--plot {ro}/run.png: cannot write in folder"),
    (DISP + ["-o", "{tmp}/x.xyz"], "cannot write an image as '.xyz'"),
    (DISP + ["-o", "{tmp}/ok.png", "--npy", "{ro}/x.npy"], "--npy {ro}/x.npy: cannot write"),
    (["tune", "--out", "{tmp}/t.toml", "--plot", "{ro}/x.png"], "--plot {ro}/x.png"),
    (["tune", "--out", "{tmp}/t.txt"], "is written as a TOML file; name it .toml"),
    (SERVO + ["--log", "{tmp}/missing/dir/run.csv"], "no such folder {tmp}/missing/dir"),
    (DISP + ["-o", "{tmp}"], "is a folder"),
    (["eval", "--picture", "{l}"], "--picture {l}: not a folder"),
    (["calibrate", "{replay}", "--ros", "{l}"], "--ros {l}: not a folder"),
    (["calibrate", "{replay}", "--ros", "{ro}/ros"], "--ros {ro}/ros: cannot make the folder"),
    (["calibrate", "{replay}", "--out", "{ro}/calib.yml"], "cannot write in folder"),
    (["capture", "--out", "{ro}"], "--out {ro}: cannot write in folder"),
    (["capture", "--out", "{ro}/shots"], "--out {ro}/shots: cannot write in folder"),
    (["capture", "--out", "{l}"], "not a folder"),
    # inputs: images
    (["disparity", "{colour}", "{r}", "-o", "{tmp}/o.png"], "is colour and"),
    (["disparity", "{tmp}", "{r}", "-o", "{tmp}/o.png"], "is a folder, not an image"),
    (["disparity", "{tmp}/none.png", "{r}", "-o", "{tmp}/o.png"], "none.png: no such file"),
    (["disparity", "{junk}", "{r}", "-o", "{tmp}/o.png"], "not a readable image"),
    (["disparity", "{l}", "{small}", "-o", "{tmp}/o.png"], "differ in size"),
    # inputs: scenes whose meta.json is hostile
    (["eval", "{scene_list}"], "meta.json: unreadable or lacks 'scale'"),
    (["eval", "{scene_zero}"], "meta.json: needs a positive 'scale'"),
    (["eval", "{scene_nan}"], "meta.json: needs a positive 'scale'"),
    (["eval", "{scene_top}"], "meta.json: needs a positive 'scale'"),
    (["eval", "{scene_blank}"], "its ground truth has no known pixel"),
    (["eval", "{scene_blank}", "--picture", "{tmp}/new"], "its ground truth has no known"),
    # inputs: params files
    (DISP + ["-o", "{tmp}/o.png", "--params", "{utf16}"], "not UTF-8 text"),
    (DISP + ["-o", "{tmp}/o.png", "--params", "{big}"], "big.toml: bad value"),
    (DISP + ["-o", "{tmp}/o.png", "--params", "{deep}"], "nested too deeply"),
    (DISP + ["-o", "{tmp}/o.png", "--params", "{notable}"], "[matcher] must be a table"),
    (DISP + ["-o", "{tmp}/o.png", "--params", "{nan}"], "must be a finite number"),
    (DISP + ["-o", "{tmp}/o.png", "--params", "{unknown}"], "unknown matcher parameter"),
    (DISP + ["-o", "{tmp}/o.png", "--params", "{tmp}/none.toml"], "cannot read"),
    # numeric options, refused at parse time naming the option
    (SERVO + ["--max-duty", "5000"], "argument --max-duty: must be >= 1 and <= 1000"),
    (SERVO + ["--fps", "0"], "argument --fps: must be >= 1"),
    (SERVO + ["--duration", "-5"], "argument --duration: must be > 0"),
    (SERVO + ["--tolerance-cm", "-1"], "argument --tolerance-cm: must be > 0"),
    (SERVO + ["--min-duty", "-100"], "argument --min-duty: must be >= 0"),
    (SERVO + ["--min-duty", "700"], "--min-duty 700 exceeds --max-duty 600"),
    (["servo", "--sim", "--trial-index", "3"], "--trial-index goes with --trials N"),
    (["servo", "--sim", "--marker-radius-cm", "4"], "the simulated world draws its own"),
    (["servo", "--sim", "--marker", "aruco"], "the simulated world draws its own"),
    (["servo", "--sim", "--nominal", "--json", "{tmp}/t.json"], "--json goes with --trials N"),
    (["servo", "--sim", "--trials", "3", "--log", "{tmp}/run.csv"],
     "--log writes one run's log: with --trials, give one --trial-index"),
    (["servo", "--sim", "--trials", "3", "--trial-index", "0", "--trial-index", "1", "--log",
      "{tmp}/run.csv"], "--log writes one run's log: with --trials, give one --trial-index"),
    (["eval", "--scale", "0"], "argument --scale: must be > 0"),
    (["eval", "--rho", "-1"], "argument --rho: must be > 0"),
    (["tune", "--scale", "-4"], "argument --scale: must be > 0"),
    (["tune", "--alpha", "nan"], "argument --alpha: must be a finite number"),
    (["tune", "--workers", "0"], "argument --workers: must be >= 1"),
    (["capture", "--count", "0", "--out", "{tmp}/shots"], "argument --count: must be >= 1"),
    (["calibrate", "{replay}", "--square", "0"], "argument --square: must be > 0"),
    (["emulate", "--drop", "1"], "argument --drop: must be >= 0 and < 1"),
    # windows and ranges of the matcher
    (DISP + ["-o", "{tmp}/o.png", "--block-size", "8"], "block size must be odd"),
    (DISP + ["-o", "{tmp}/o.png", "--block-size", "0"], "argument --block-size: must be >= 1"),
    (DISP + ["-o", "{tmp}/o.png", "--num-disparities", "900"], "wider than the image"),
    (DISP + ["-o", "{tmp}/o.png", "--uniqueness-ratio", "101"], "argument --uniqueness-ratio"),
    # ports
    (["servo", "--camera", "replay:{replay}", "--port", "{tmp}/no-such-port"],
     "no-such-port: no such device"),
    # the simulated Uno's flash: saved where it can be, and only for --uno
    (["emulate", "--uno", "--flash", "{tmp}/nodir/f.bin"], "--flash {tmp}/nodir/f.bin: no such"),
    (["emulate", "--flash", "{tmp}/f.bin"], "--flash is the simulated Uno's flash"),
    (["servo", "--sim", "--flash", "{tmp}/f.bin"], "--flash is the simulated Uno's flash: it goes "
     "with --robot uno"),
    # images of two depths; ground truth PFMs and calib.txt that are wrong in their own ways
    (["disparity", "{l16}", "{l}", "-o", "{tmp}/o.png"], "l16.png: a 16-bit image"),
    (["eval", "{pfm_abc}"], "PFM size 'abc 5' is not two positive integers"),
    (["eval", "{pfm_negsize}"], "PFM size '-160 120' is not two positive integers"),
    (["eval", "{pfm_colour}"], "disp0GT.pfm: a colour PFM (PF)"),
    (["eval", "{pfm_nan}"], "PFM scale 'nan' is not a finite non-zero number"),
    (["eval", "{pfm_negative}"], "negative disparities (down to -49 px)"),
    (["eval", "{pfm_unknown}"], "disp0GT.pfm: no known disparity"),
    (["eval", "{calib_banana}"], "calib.txt: ndisp='banana' is not a number"),
    # calibrations: a YAML list, three names, an OpenCV file given as a ROS one, fisheye
    (SERVO + ["--calib", "{calib_list}"], "list.yml: not an OpenCV calibration file (its top"),
    (SERVO + ["--calib", "a,b,c"], "--calib a,b,c: give one OpenCV file, or two ROS"),
    (SERVO + ["--calib", "{calib_ocv},{ros_equi}"], "calib.yml is an OpenCV stereo calibration"),
    (SERVO + ["--calib", "{ros_equi},{ros_equi}"], "distortion_model 'equidistant' is not"),
    # a replay whose left and right are swapped: refused before the robot moves
    (["servo", "--camera", "replay:{swapped}", "--port", "emulator"],
     "replay:{swapped}: left and right look swapped (median disparity -"),
    (["view", "--camera", "replay:{swapped}"], "replay:{swapped}: left and right look swapped"),
    (["tune", "--camera", "replay:{swapped}", "--objective", "self"],
     "replay-0: left and right look swapped"),
    # cameras: a sysfs root that is not there
    (["cameras", "--sysfs", "{tmp}/missing"], "--sysfs {tmp}/missing: no such folder"),
    # Ray: an address where nothing listens answers at once (loopback only)
    *([(["tune", "--ray", "127.0.0.1:1"], "--ray 127.0.0.1:1: no Ray cluster answers there")]
      if importlib.util.find_spec("ray") else []),
]


@pytest.mark.parametrize("argv, words", ROWS, ids=[" ".join(r[0][:1] + r[0][-2:])
                                                     for r in ROWS])
def test_bad_input_is_one_line_exit_2_and_writes_nothing(
        argv: list[str], words: str, files: dict[str, Path], ro: Path, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    names = {k: str(v) for k, v in files.items()} | {"tmp": str(tmp_path), "ro": str(ro)}
    fill = [a.format(**names) for a in argv]
    inputs = files["l"].parent
    before, inputs_before = _tree(tmp_path), _tree(inputs)
    code, err = _run(fill, capsys)
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert words.format(**names) in err
    assert _tree(tmp_path) == before  # nothing written, nothing touched
    assert _tree(inputs) == inputs_before  # and the inputs (shared by the file's tests) as made
    for root in (tmp_path, inputs):
        assert not any(p.name.startswith(".") for p in root.rglob("*"))  # no temporaries


def _scene(folder: Path, meta: object, blank: bool = False) -> Path:
    """A scene in the shared layout with this meta.json (blank: ground truth all unknown)."""
    s = synthetic_scene(seed=3, width=96, height=64, max_disp=12)
    folder.mkdir()
    cv2.imwrite(str(folder / "left.png"), s.left)
    cv2.imwrite(str(folder / "right.png"), s.right)
    gt = np.nan_to_num(s.gt * 4).astype(np.uint8) * (not blank)
    cv2.imwrite(str(folder / "disp_left.png"), gt)
    (folder / "meta.json").write_text(json.dumps(meta))
    return folder


@pytest.mark.parametrize("name, file", [("../escaped", "_escaped.png"),
                                        ("/tmp/abs/x", "_tmp_abs_x.png"),
                                        ("..", "unnamed.png")])
def test_a_picture_named_from_data_stays_inside_the_folder(
        tmp_path: Path, name: str, file: str, capsys: pytest.CaptureFixture[str]) -> None:
    scene = _scene(tmp_path / "scene", {"scale": 4, "scene": name})
    out = tmp_path / "deep" / "out"
    out.mkdir(parents=True)
    before = _tree(tmp_path)
    assert main(["eval", str(scene), "--picture", str(out), "--num-disparities", "16"]) == 0
    new = set(_tree(tmp_path)) - set(before)
    assert new == {f"deep/out/{file}"}
    assert not Path("/tmp/abs/x.png").exists()


def test_picture_and_ros_folders_are_made_as_capture_makes_its_own(tmp_path: Path) -> None:
    scene = _scene(tmp_path / "scene", {"scale": 4, "scene": "s"})
    out = tmp_path / "new" / "pictures"
    assert main(["eval", str(scene), "--picture", str(out), "--num-disparities", "16"]) == 0
    assert [p.name for p in out.iterdir()] == ["s.png"]


@pytest.mark.parametrize("umask", [0o022, 0o002])
def test_an_overwritten_output_gets_the_umask_mode(tmp_path: Path, umask: int) -> None:
    out = tmp_path / "p.toml"
    out.write_text("old")
    out.chmod(0o600)
    old = os.umask(umask)
    try:
        write_text_atomic(out, "new")
        with all_or_nothing():
            write_text_atomic(tmp_path / "q.toml", "new")
    finally:
        os.umask(old)
    assert out.read_text() == "new"
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask
    assert (tmp_path / "q.toml").stat().st_mode & 0o777 == 0o666 & ~umask


def test_all_or_nothing_writes_nothing_when_the_block_fails(tmp_path: Path) -> None:
    first, second = tmp_path / "a.toml", tmp_path / "gone" / "b.toml"
    (tmp_path / "gone").mkdir()
    with contextlib.suppress(HostError), all_or_nothing():
        write_text_atomic(first, "a")
        raise HostError("the command failed after its first output")
    assert list(tmp_path.iterdir()) == [tmp_path / "gone"]
    with pytest.raises(HostError, match="does not exist"), all_or_nothing():
        write_text_atomic(first, "a")
        write_text_atomic(second, "b")
        (tmp_path / "gone").rmdir()  # the second output's folder vanishes before the commit
    assert list(tmp_path.iterdir()) == []


def test_a_wrapped_ctrl_c_is_an_interruption_not_a_traceback() -> None:
    try:  # numba's parallel code can surface Ctrl-C as a SystemError with it as the context
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise SystemError("returned a result with an exception set") from None
    except SystemError as e:
        e.__context__ = KeyboardInterrupt()
        assert describe(e) == (130, "interrupted")
    assert describe(AssertionError("a bug")) is None  # a bug keeps its traceback


def test_debug_shows_the_traceback(files: dict[str, Path], tmp_path: Path) -> None:
    argv = ["disparity", str(files["l"]), str(files["small"]), "-o", str(tmp_path / "o.png")]
    with pytest.raises(HostError, match="differ in size"):
        main(["--debug", *argv])
    with pytest.raises(HostError):
        main([*argv, "--debug"])


def test_sigterm_during_tune_is_an_interruption_that_writes_nothing(tmp_path: Path,
                                                                   capsys) -> None:
    late: list[int] = []
    guard = signal.signal(signal.SIGTERM, lambda n, _: late.append(n))  # a late one is harmless
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGTERM))
    out = tmp_path / "t.toml"
    try:
        timer.start()
        code = main(["tune", "--space", "sad", "--method", "grid", "--out", str(out)])  # minutes
    finally:
        timer.cancel()
        signal.signal(signal.SIGTERM, guard)
    assert late == [] and code == 128 + signal.SIGTERM
    assert capsys.readouterr().err == "host tune: interrupted (SIGTERM)\n"
    assert list(tmp_path.iterdir()) == []


def test_an_erased_uno_resetting_over_and_over_is_said_once(capsys) -> None:
    from host.commands.emulate import RESET_LINES_PER_S, _ResetLines
    from host.emulator.uno import Reset

    lines = _ResetLines()
    for i in range(60):  # what an erased chip does in one second
        lines.add(Reset(i * 266_000, 0x02), 100.0 + i / 60)
    err = capsys.readouterr().err.splitlines()
    assert len(err) == RESET_LINES_PER_S + 1 and "keeps resetting" in err[-1]
