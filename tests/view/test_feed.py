"""The view's feed: the loop hands it snapshots without waiting; it encodes only for a page
that asks, at most max_fps, and counts what a slow page misses."""

from __future__ import annotations

import json
import threading
import time

import cv2
import numpy as np

from host.view.feed import ViewFeed
from tests.view.snapshots import snapshot


def test_nothing_is_encoded_without_a_page():
    feed = ViewFeed()
    try:
        for i in range(50):
            feed(snapshot(t=i / 30))
        time.sleep(0.2)
        assert feed.snapshots == 50 and feed.encoded == 0 and feed.dropped == 0
    finally:
        feed.close()


def test_a_slow_page_gets_the_latest_and_the_rest_are_counted_dropped():
    feed = ViewFeed(max_fps=10)
    feed.watch(True)
    try:
        stop = threading.Event()
        got = []

        def page():
            seq = 0
            while not stop.is_set():
                update = feed.wait_update(seq, 0.2)
                if update is not None:
                    seq = update.seq
                    got.append(update)

        reader = threading.Thread(target=page, daemon=True)  # a failed test must not hang pytest
        reader.start()
        worst = 0.0
        for i in range(300):  # a 300 Hz loop against a page of at most 10 updates a second
            t0 = time.perf_counter()
            feed(snapshot(t=i / 300))
            worst = max(worst, time.perf_counter() - t0)
            time.sleep(1 / 300)
        time.sleep(0.3)
        stop.set()
        reader.join()
        assert 0 < feed.encoded < 40  # about 10 a second, not 300
        assert feed.dropped >= 300 - feed.encoded - 2
        assert worst < 0.05  # the observer never waits for the encoder
        last = got[-1]
        assert last.seq == 300  # the page ends up with the newest step
        json.dumps(last.state, allow_nan=False)
        left = cv2.imdecode(np.frombuffer(last.images[0], np.uint8), cv2.IMREAD_COLOR)
        disp = cv2.imdecode(np.frombuffer(last.images[1], np.uint8), cv2.IMREAD_COLOR)
        assert left.shape == disp.shape == (240, 320, 3)
    finally:
        feed.watch(False)
        feed.close()


def test_plot_samples_cover_the_last_history_seconds():
    feed = ViewFeed(history_s=2.0)
    try:
        for i in range(100):
            feed(snapshot(t=i * 0.1, robot_px=float("nan") if i == 99 else 20.0))
        samples = feed.samples_since(-1.0)
        assert samples[0][0] >= 9.9 - 2.0 - 1e-9 and samples[-1][0] == 9.9
        assert samples[-1][2] is None  # no marker, no robot depth
        assert samples[-2][3:] == [300, 310]
        assert feed.samples_since(9.85) == [samples[-1]]
    finally:
        feed.close()
