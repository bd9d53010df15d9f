"""Property tests of the host's framing and messages (hypothesis)."""

from __future__ import annotations

from dataclasses import fields

from hypothesis import given, settings
from hypothesis import strategies as st

from host.link import protocol_gen as gen
from host.link.frame import FrameDecoder, encode_frame
from host.link.messages import pack, unpack


@st.composite
def messages(draw):
    cls = draw(st.sampled_from(sorted(gen.MESSAGES.values(), key=lambda c: c.ID)))
    values = {f.name: draw(st.integers(*cls.RANGES[f.name])) for f in fields(cls)}
    return cls(**values)


@given(messages(), st.integers(0, 255))
def test_every_message_round_trips_through_a_frame(msg, seq: int) -> None:
    msg_id, payload = pack(msg)
    frames = FrameDecoder().feed(encode_frame(seq, msg_id, payload))
    assert len(frames) == 1 and frames[0].seq == seq
    assert unpack(frames[0].id, frames[0].payload) == msg


@settings(max_examples=300)
@given(messages(), st.integers(0, 255), st.data())
def test_corrupted_frames_are_never_accepted_as_another_frame(msg, seq: int, data) -> None:
    frame = bytearray(encode_frame(seq, *pack(msg)))
    positions = data.draw(st.lists(st.integers(0, len(frame) - 1), min_size=1, max_size=3,
                                   unique=True))
    for pos in positions:
        frame[pos] ^= data.draw(st.integers(1, 255))
    for f in FrameDecoder().feed(bytes(frame)):
        assert (f.seq, f.id, f.payload) == (seq, *pack(msg))


@given(st.binary(max_size=80), messages(), st.integers(0, 255))
def test_after_any_garbage_the_next_valid_frame_is_decoded(garbage: bytes, msg, seq) -> None:
    frame = encode_frame(seq, *pack(msg))
    # padding completes a false frame that the garbage may have opened, as later traffic would
    frames = FrameDecoder().feed(garbage + frame + bytes(gen.HEADER_LEN + gen.MAX_PAYLOAD + 2))
    assert frames and (frames[-1].seq, frames[-1].id, frames[-1].payload) == (seq, *pack(msg))


def test_out_of_range_fields_are_refused_both_ways() -> None:
    import pytest

    from host.link.messages import ProtocolError

    with pytest.raises(ProtocolError, match="SET_DRIVE.left = 1001"):
        pack(gen.SetDrive(left=1001, right=0))
    with pytest.raises(ProtocolError) as e:
        unpack(gen.SetConfig.ID, (10).to_bytes(2, "little") + bytes(2))
    assert e.value.code == gen.Error.OUT_OF_RANGE
