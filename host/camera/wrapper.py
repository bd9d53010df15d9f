"""A source that hands on another's pairs (paced, recorded, ...): what it does not say itself,
the inner source says: its own attributes, its description, and closing it."""

from __future__ import annotations

from typing import Any

from host.camera.source import StereoSource


class WrappedSource(StereoSource):
    """inner's pairs through this source's _read; inner's attributes (clock, t, ended, ...)
    read through, its describe() and close() used."""

    def __init__(self, inner: StereoSource) -> None:
        self.inner = inner

    def __getattr__(self, name: str) -> Any:  # only for names the wrapper does not have
        if name == "inner":  # not set yet: no endless lookup
            raise AttributeError(name)
        return getattr(self.inner, name)

    def describe(self) -> dict[str, Any]:
        return self.inner.describe()

    def close(self) -> None:
        self.inner.close()
