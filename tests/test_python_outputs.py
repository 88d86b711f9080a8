"""What the Python API writes: a file it cannot write is an OutputError naming the file and
the system's reason, and nothing partial is left (a full file system here: a small tmpfs)."""

from __future__ import annotations

import frictiondyn as fd
import numpy as np
import pytest
from conftest import chain, deck_text


def oscillator(duration: float, out: str) -> dict:
    return chain(10, duration, name="osc", out=out)


def test_to_npz_adds_the_suffix_and_reads_back(tmp_path):
    deck = tmp_path / "osc.nml"
    deck.write_text(deck_text(oscillator(0.2, str(tmp_path / "out"))))
    r = fd.run(deck)
    path = r.to_npz(tmp_path / "res")
    assert path == tmp_path / "res.npz" and path.is_file()
    back = fd.Result.from_npz(path)
    assert back.names == r.names and np.array_equal(back.data, r.data)
    assert back.summary == r.summary
    assert sorted(p.name for p in tmp_path.iterdir()) == ["osc.nml", "res.npz"]


def test_to_npz_on_a_full_file_system_is_an_output_error_and_keeps_the_earlier_file(tmp_path, small_fs):
    """A first small Result fits; a second, about 2 MB, does not: OutputError naming the
    file and the disk being full; the first file is untouched and no temporary is left."""
    deck = tmp_path / "osc.nml"
    deck.write_text(deck_text(oscillator(0.2, str(tmp_path / "out"))))
    small = fd.run(deck)
    small.to_npz(small_fs / "r.npz")
    before = (small_fs / "r.npz").read_bytes()
    deck.write_text(deck_text(oscillator(40.0, str(tmp_path / "out"))))
    big = fd.run(deck)
    with pytest.raises(fd.OutputError, match=r"cannot write '.*r\.npz': No space left on device"):
        big.to_npz(small_fs / "r.npz")
    assert [p.name for p in small_fs.iterdir()] == ["r.npz"]
    assert (small_fs / "r.npz").read_bytes() == before


def test_a_stream_that_cannot_be_written_is_an_output_error(tmp_path, small_fs):
    """Session.stream to a full file system: the write fails during the solve, which raises
    OutputError (an output that cannot be written, not a failure of the solver) naming the
    file and the system's reason; no temporary is left."""
    deck = tmp_path / "osc.nml"
    deck.write_text(deck_text(oscillator(40.0, str(small_fs))))
    with fd.Session(deck) as s:
        s.stream()
        with pytest.raises(fd.OutputError, match=r"cannot write '.*\.osc\.csv\..*': No space left on device"):
            s.solve(history=False)
    assert list(small_fs.iterdir()) == []
