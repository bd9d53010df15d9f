"""compute_disparity: one entry point for every matcher (own SAD/SSD/NCC and OpenCV's)."""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator

import cv2
import numba
import numpy as np
from numpy.typing import DTypeLike

from host.errors import HostError
from host.stereo import block_matching as bm
from host.stereo import sad, sgm
from host.stereo.cost import census_ad_volume, integer_term, match_histogram, reversed_planes
from host.stereo.grey import to_grey
from host.stereo.heap import keep_freed_blocks
from host.stereo.opencv_backend import opencv_disparity
from host.stereo.params import MatcherParams
from host.stereo.postprocess import fill_background, lr_consistency, median
from host.stereo.subpixel import DEFAULT_FITS, FIT_NONE, FITS

SGM_P1 = 8  # default SGM penalties per pixel of the cost box (census bits)
SGM_P2 = 32
SGM_MIXED_P1 = 18  # the same with the intensity term (MatcherParams.intensity_weight > 0)
SGM_MIXED_P2 = 72
# the base P2 (at no grey step) of an adaptive P2 (MatcherParams.p2_adapt > 0): 16/9 of the
# fixed one, so a step of p2_adapt grey levels gets about the fixed P2's half (docs/stereo.md)
SGM_ADAPTIVE_P2 = 56
SGM_MIXED_ADAPTIVE_P2 = 128
# pixel-disparities (about 1.5 ms of SAD on one core) below which a match runs on the calling
# thread alone: waking numba's thread pool costs more than it saves there, and on a loaded
# machine a sleeping worker took 7-40 ms to join a 0.2 ms match of the servo's marker window
SERIAL_WORK = 1 << 21
keep_freed_blocks()  # per-call arrays reuse the last call's memory (heap.py)


@contextlib.contextmanager
def numba_threads(n: int) -> Iterator[None]:
    """numba's thread count for kernels called from this thread (it is per thread) inside
    (left alone when it is n already: the servo's ~1300 one-thread matches a trial each paid
    two set_num_threads, ~3 us each)."""
    before = numba.get_num_threads()
    if before == n:
        yield
        return
    numba.set_num_threads(n)
    try:
        yield
    finally:
        numba.set_num_threads(before)


def _box_sums(img: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    f = img.astype(np.float64)
    s = cv2.boxFilter(f, cv2.CV_64F, (size, size), normalize=False,
                      borderType=cv2.BORDER_CONSTANT)
    sq = cv2.boxFilter(f * f, cv2.CV_64F, (size, size), normalize=False,
                       borderType=cv2.BORDER_CONSTANT)
    return s, sq


def _planes(image: np.ndarray, colour: bool, view: bool = False) -> np.ndarray:
    """uint8 (channels, rows, cols): BGR planes when colour is asked for and present, else grey;
    view: the colour planes as a view of image (no copy, not contiguous)."""
    if colour and image.ndim == 3 and image.shape[2] >= 3 and image.dtype == np.uint8:
        planes = np.moveaxis(image[:, :, :3], 2, 0)
        return planes if view else np.ascontiguousarray(planes)
    return to_grey(image)[None]


def own_disparity(left: np.ndarray, right: np.ndarray, p: MatcherParams) -> np.ndarray:
    """The project's own matchers: the paper's block matcher (SAD, or SSD / ZNCC) with WTA,
    sub-pixel and LR check, or census + semi-global matching (SGM, host/stereo/sgm.py).

    SAD and SSD sum the cost over the colour channels when p.colour is set; NCC uses grey.
    """
    if p.matcher == "sad":
        return sad_disparity(left, right, p)
    if p.matcher == "sgm":
        return sgm_disparity(left, right, p)
    kind = bm.COSTS[p.matcher]
    colour = p.colour and kind != bm.COST_NCC
    pl, pr = _planes(left, colour), _planes(right, colour)
    if kind == bm.COST_NCC:
        left, right = pl[0], pr[0]
        sl, ql = _box_sums(left, p.block_size)
        sr, qr = _box_sums(right, p.block_size)
    else:
        sl = ql = sr = qr = np.zeros((1, 1))
    want_right = p.lr_check is not None
    disp_l, disp_r = bm.match_rows(pl, pr, p.min_disparity, p.num_disparities,
                                   p.block_size // 2, kind, float(p.uniqueness_ratio),
                                   subpixel_fit(p), want_right, p.border == "clip",
                                   sl, ql, sr, qr)
    if p.lr_check is not None:  # want_right
        disp_l = lr_consistency(disp_l, disp_r, float(p.lr_check))
    out: np.ndarray = disp_l
    return out


def subpixel_fit(p: MatcherParams) -> int:
    """The sub-pixel fit p asks for: none, its own choice, or the measured default for its cost."""
    if not p.subpixel:
        return FIT_NONE
    return FITS[DEFAULT_FITS[p.matcher] if p.subpixel_fit == "auto" else p.subpixel_fit]


def sad_disparity(left: np.ndarray, right: np.ndarray, p: MatcherParams) -> np.ndarray:
    """The own SAD matcher (host/stereo/sad.py), summed over colour channels if p.colour."""
    pl, pr = _planes(left, p.colour), _planes(right, p.colour)
    cdt, wdt = sad.lane_types(pl.shape[0], p.block_size)
    want_right = p.lr_check is not None
    work = pl.shape[1] * pl.shape[2] * p.num_disparities
    n = 1 if work < SERIAL_WORK else numba.get_num_threads()
    with numba_threads(n):
        disp_l, disp_r = sad.match_sad(pl, pr, p.min_disparity, p.num_disparities,
                                       p.block_size // 2, float(p.uniqueness_ratio),
                                       subpixel_fit(p), want_right, p.border == "clip",
                                       np.empty(0, cdt), np.empty(0, wdt), np.iinfo(wdt).max, n)
    if p.lr_check is not None:  # want_right
        disp_l = lr_consistency(disp_l, disp_r, float(p.lr_check))
    out: np.ndarray = disp_l
    return out


def sgm_penalties(p: MatcherParams) -> tuple[int, int]:
    """(P1, P2) for the own SGM: p.p1 / p.p2 when set, else the defaults per pixel of the cost
    box: SGM_P1 / SGM_P2 for census alone, SGM_MIXED_P1 / SGM_MIXED_P2 with the intensity term
    (its costs span more; measured on the ten shared scenes, docs/stereo.md); with an
    adaptive P2 (p.p2_adapt) the base P2 is SGM_ADAPTIVE_P2 / SGM_MIXED_ADAPTIVE_P2."""
    area = p.block_size ** 2
    mixed = p.intensity_weight > 0
    base1 = SGM_MIXED_P1 if mixed else SGM_P1
    if p.p2_adapt > 0:
        base2 = SGM_MIXED_ADAPTIVE_P2 if mixed else SGM_ADAPTIVE_P2
    else:
        base2 = SGM_MIXED_P2 if mixed else SGM_P2
    p1 = p.p1 or base1 * area
    return p1, max(p.p2 or base2 * area, p1)


_VOLUMES = threading.local()
KEEP_BYTES = 512 << 20  # sum volumes up to this size are kept for the next call of the same size
KEEP_FOUR_BYTES = 64 << 20  # the same for the 4-path buffers (17 MiB at 1280x960 / 128)


def _sgm_sums(shape: tuple[int, ...], nd: int, dtype: DTypeLike = np.uint16) -> np.ndarray:
    """The path-sum volume for SGM (uint16) or its kept cost rows (uint8), reused by the next
    call on the same size in this thread: a fresh 39 MB costs several ms of page faults per
    call at 640x480 / 64, a fresh 315 MB at 1280x960 / 128 (the 4-path default) 809 faults and
    271 ms of system time (KEEP_BYTES was 128 MiB then: 905 ms a call on one thread against 550
    with it kept, load 12)."""
    key = (shape[0], shape[1], nd)
    if not key[0]:
        return np.empty(key, dtype=dtype)
    kept: dict[str, np.ndarray] | None = getattr(_VOLUMES, "kept", None)
    if kept is None:
        kept = _VOLUMES.kept = {}
    got = kept.get(np.dtype(dtype).char)
    if got is not None and got.shape == key:
        return got
    kept.pop(np.dtype(dtype).char, None)
    out = np.empty(key, dtype=dtype)
    if out.nbytes <= KEEP_BYTES:
        kept[np.dtype(dtype).char] = out
    return out


def _four_path(shape: tuple[int, ...], nd: int, cmax: int, p2: int, rows_made: bool,
               stripes: int) -> sgm.FourPath:
    """The 4-path pass's buffers (sgm.FourPath), reused by the next call of the same size and
    costs in this thread (so its blocks take no fresh pages: no page faults in steady state)
    up to KEEP_FOUR_BYTES; larger ones are made per call, so they are not held through the
    post-processing (at 2560x1920 / 256 they are 20 bytes a pixel)."""
    key = (shape[0], shape[1], nd, cmax, p2, rows_made, stripes)
    kept = getattr(_VOLUMES, "four", None)
    if kept is not None and kept[0] == key:
        got: sgm.FourPath = kept[1]
        return got
    _VOLUMES.four = None
    out = sgm.FourPath.make(shape[0], shape[1], nd, cmax, p2, rows_made, stripes)
    if sum(a.nbytes for a in out[1:]) <= KEEP_FOUR_BYTES:
        _VOLUMES.four = (key, out)
    return out


NO_VOLUME = sgm.NO_VOLUME


def sgm_disparity(left: np.ndarray, right: np.ndarray, p: MatcherParams) -> np.ndarray:
    """The own census + semi-global matcher (host/stereo/sgm.py): census of grey, the
    intensity term on colour (p.colour) or grey. The cost comes from
    the census rows inside the aggregation when it is census alone (window 1), else from a
    cost volume (host/stereo/cost.py: the intensity term, the outside cost; the box sum).
    Without a volume the passes make the census rows they need from the padded grey images
    (16 bytes a pixel of census images not kept), and the LR check runs row by row (no right
    map kept)."""
    gl, gr = [cv2.copyMakeBorder(to_grey(v), sgm.CENSUS_H, sgm.CENSUS_H, sgm.CENSUS_W,
                                 sgm.CENSUS_W, cv2.BORDER_REPLICATE) for v in (left, right)]
    grey = gl  # the image steps of an adaptive P2 (kept when the cost is in a volume)
    shape = left.shape[:2]
    cl, cr = sgm.NO_CENSUS, sgm.NO_CENSUS
    vol, planes, rplanes, term = NO_VOLUME, sgm.NO_PLANES, sgm.NO_PLANES, sgm.census_term()
    if p.intensity_weight > 0 or p.outside_cost != sgm.CENSUS_BITS:
        # the left planes as a view of the image where it has colour (3 bytes a pixel less)
        pl, pr = _planes(left, p.colour, view=True), _planes(right, p.colour)
        # the intensity term sees the right image with the left one's levels (per channel),
        # the table taken from the columns both cameras see (not the strip beside each edge)
        cut = min(p.min_disparity + p.num_disparities, shape[1] // 2)
        pr = np.stack([match_histogram(b, a, b[:, :b.shape[1] - cut], a[:, cut:])
                       for a, b in zip(pl, pr)])
        weight = float(p.intensity_weight)
        fused = None
        if p.block_size == 1 and pl.shape[0] in (1, 3):
            fused = integer_term(pl.shape[0], weight, p.intensity_cap, p.outside_cost)
        if fused is not None:
            # the cost row by row inside the aggregation: no cost volume
            term = fused
            planes, rplanes = pl, reversed_planes(pr, p.min_disparity, p.num_disparities)
        else:
            term = sgm.census_term()
            cl, cr = sgm.census(gl), sgm.census(gr)
            vol = np.empty((*shape, p.num_disparities), dtype=np.uint16)
            vol = census_ad_volume(cl, cr, pl, pr, p.min_disparity, weight, p.intensity_cap,
                                   p.outside_cost, vol)
        del pr  # reversed (rplanes) or in the volume: 3 bytes a pixel less at the peak
    elif p.block_size > 1:
        cl, cr = sgm.census(gl), sgm.census(gr)
        vol = np.empty((*shape, p.num_disparities), dtype=np.uint16)
        vol = sgm.hamming_volume(cl, cr, p.min_disparity, vol)
    if p.block_size > 1:
        vol = sgm.box_sum(vol, p.block_size)
    if vol.shape[0]:
        gl, gr = sgm.NO_GREY, sgm.NO_GREY  # the cost is in the volume
    p1, p2 = sgm_penalties(p)
    want_right = p.lr_check is not None
    # only the 8-path scheme keeps a sum volume; the 5- and 4-path passes decide each row as
    # they go (the 4-path one from a stored row of its path from the bottom every K rows)
    sums = _sgm_sums(shape if p.paths == 8 else (0, 0), p.num_disparities)
    # with 8 paths each cost row is kept (uint8) for the second direction: made once
    costs = sgm.NO_COSTS
    if p.paths == 8 and vol.shape[0] == 0 and term[5] <= 255:
        costs = _sgm_sums(shape, p.num_disparities, np.uint8)
    four = _four_path(shape, p.num_disparities, sgm.largest_cost(vol, term), p2,
                      vol.shape[0] == 0, (1 if numba.get_num_threads() < 2 else 2)
                      if p.paths == 4 else 0)
    crrev = sgm.reversed_right(cr, p.min_disparity, p.num_disparities) if cr.size else cr
    del cr  # 8 bytes a pixel less at the peak (with a volume)
    # the right map has whole pixels: with a sub-pixel left map a tolerance under half a
    # pixel (LR 0, the default) means the same winner, not no sub-pixel result at all
    tol = -1.0 if p.lr_check is None else float(p.lr_check)
    lr = max(tol, 0.5) if subpixel_fit(p) and tol >= 0 else tol
    disp_l, _ = sgm.match(cl, crrev, vol, sums, p.min_disparity, np.uint16(p1), np.uint16(p2),
                          p.paths, float(p.uniqueness_ratio), subpixel_fit(p), want_right,
                          False, planes, rplanes, term, costs, four, gl, gr, lr,
                          float(p.p2_adapt), grey)
    if p.border == "invalid":
        # the census (and box) window of these pixels leaves the image
        ry, rx = sgm.CENSUS_H + p.block_size // 2, sgm.CENSUS_W + p.block_size // 2
        disp_l[:ry] = disp_l[-ry:] = np.nan
        disp_l[:, :rx] = disp_l[:, -rx:] = np.nan
    return disp_l


def compute_disparity(left: np.ndarray, right: np.ndarray, params: MatcherParams) -> np.ndarray:
    """Disparity of the left view in px, float32, NaN = invalid. Colour input is converted."""
    if left.shape[:2] != right.shape[:2]:
        raise HostError(f"left and right images differ in size: {left.shape[1]}x{left.shape[0]}"
                        f" vs {right.shape[1]}x{right.shape[0]}")
    p = params.validate(width=left.shape[1])
    if p.matcher.startswith("opencv"):
        disp = opencv_disparity(left, right, p)
    else:
        disp = own_disparity(left, right, p)
    if p.fill:
        disp = fill_background(disp)
    if p.median:
        disp = median(disp, p.median)
    return disp


def matched_on(image: np.ndarray, p: MatcherParams) -> str:
    """"colour" when the matcher p names matches on image's BGR channels, else "grey"."""
    colour = p.colour and (p.matcher in ("sad", "ssd", "opencv-sgbm")
                           or (p.matcher == "sgm" and p.intensity_weight > 0))
    return "colour" if colour and image.ndim == 3 and image.shape[2] >= 3 else "grey"


def warm_up(params: MatcherParams) -> None:
    """Compile (or load from numba's cache) the kernels params needs, so timings exclude it."""
    rng = np.random.default_rng(0)
    size = (24, 48 + params.block_size + params.min_disparity, 3)
    img = rng.integers(0, 255, size, dtype=np.uint8)
    compute_disparity(img, img, params.replace(num_disparities=16))
