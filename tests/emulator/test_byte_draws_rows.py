"""The line's fault draws taken a run of bytes at a time (ByteDraws.rows, issue 25) are at()'s,
byte for byte, across the blocks' borders and in both directions; and the faulty line built on
them drops and corrupts the same bytes as one draw a byte did."""

from __future__ import annotations

from host.emulator.emulator import ByteDraws, Emulator, Faults


def test_rows_are_the_draws_at_each_byte() -> None:
    d = ByteDraws(7)
    for direction, n0, count in [(0, 0, 13), (1, 4090, 12), (0, 8180, 4100), (1, 3, 1),
                                 (0, 4096, 0), (1, 12286, 3)]:
        got = d.rows(direction, n0, count)
        want = [d.at(direction, n) for n in range(n0, n0 + count)]
        assert [(a, b, 1 + int(c * 255)) for a, b, c in got] == want, (direction, n0, count)


class PerByte(Emulator):
    """The faulty line as it drew one byte at a time (the reference)."""

    def _faulty(self, data: bytes, direction: int) -> list[int]:
        f = self.faults
        n0 = self._sent[direction]
        self._sent[direction] += len(data)
        out = []
        for i, b in enumerate(data):
            drop, corrupt, xor = self._draws.at(direction, n0 + i)
            if drop < f.drop:
                continue
            out.append(b ^ xor if corrupt < f.corrupt else b)
        return out


def _line(cls: type[Emulator], data: list[bytes], faults: Faults) -> list[list[int]]:
    emu = cls(faults)
    return [emu._faulty(chunk, k % 2) for k, chunk in enumerate(data)]


def test_faulty_line_hits_the_same_bytes() -> None:
    data = [bytes((k * 37 + i) % 256 for i in range(5 + k % 23)) for k in range(900)]
    faults = Faults(drop=0.05, corrupt=0.04, seed=11)
    got = _line(Emulator, data, faults)
    assert got == _line(PerByte, data, faults)
    assert sum(map(len, got)) < sum(map(len, data))  # some bytes were dropped
