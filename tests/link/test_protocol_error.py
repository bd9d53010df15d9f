"""A message the protocol refuses, reaching the command line, is one line and exit status 2."""

import pytest

from host.cli import main
from host.commands import tune
from host.link import protocol_gen as gen
from host.link.messages import pack


def test_a_protocol_error_reaching_the_cli_is_one_line_and_exit_2(monkeypatch, capsys):
    def run(args):
        pack(gen.SetDrive(left=1001, right=0))

    monkeypatch.setattr(tune, "run", run)
    assert main(["tune"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("host tune: error: SET_DRIVE.left = 1001")


def test_the_protocol_error_keeps_its_code():
    from host.link.messages import ProtocolError

    with pytest.raises(ProtocolError) as e:
        pack(gen.SetDrive(left=0, right=-1001))
    assert e.value.code == gen.Error.OUT_OF_RANGE
