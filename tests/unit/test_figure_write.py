"""A figure that cannot be written says why (no space left), not what matplotlib's writer
raised while ending the file."""

from __future__ import annotations

import errno
import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from bayesfo.errors import OutputError  # noqa: E402
from bayesfo.outdir import staged_run  # noqa: E402
from bayesfo.plotting.output import save_figure  # noqa: E402


class _FullDisk(io.BytesIO):
    """A file that takes ``room`` bytes, then fails with ENOSPC."""

    def __init__(self, room: int):
        super().__init__()
        self.room = room

    def write(self, data):
        if self.tell() + len(data) > self.room:
            raise OSError(errno.ENOSPC, "No space left on device")
        return super().write(data)


@pytest.fixture
def full_disk(monkeypatch):
    """PDF files written through matplotlib get ``room`` bytes, as on a device that fills up
    during the write (the PDF writer opens its file through cbook.to_filehandle)."""
    from matplotlib import cbook

    real = cbook.to_filehandle

    def set_room(room):
        def to_filehandle(fname, flag="r", return_opened=False, encoding=None):
            if str(fname).endswith(".pdf") and "w" in flag:
                fh = _FullDisk(room)
                return (fh, True) if return_opened else fh
            return real(fname, flag, return_opened, encoding)

        monkeypatch.setattr(cbook, "to_filehandle", to_filehandle)

    return set_room


def _figure():
    fig, ax = plt.subplots()
    ax.plot([1, 2, 3])
    ax.set_title("x" * 50)
    return fig


@pytest.mark.parametrize("room", [200, 1000, 3000])
def test_no_space_left_during_a_pdf_write_is_said(full_disk, tmp_path, room):
    # Past the first bytes the writer's own clean-up fails (zlib "inconsistent stream state",
    # "'Stream' object has no attribute 'pos'"); the error raised is the full disk's.
    full_disk(room)
    with pytest.raises(OSError) as caught:
        save_figure(_figure(), tmp_path / "figure.pdf", close=True)
    assert caught.value.errno == errno.ENOSPC
    assert list(tmp_path.iterdir()) == []  # no temporary file left


def test_a_run_whose_figures_meet_a_full_disk_ends_with_one_line(full_disk, tmp_path):
    full_disk(3000)
    out = tmp_path / "out"
    with pytest.raises(OutputError, match=r"no space left on the device of .*out'; the earlier "
                                          "outputs there are kept"):
        with staged_run(out) as new:
            save_figure(_figure(), new / "figures" / "bode.pdf", close=True)
    assert not out.exists()  # a first run that fails leaves no directory behind


def test_the_formats_checked_without_matplotlib_are_ones_it_writes():
    from matplotlib.backend_bases import FigureCanvasBase

    from bayesfo.errors import InputError
    from bayesfo.plotting.output import ALWAYS_WRITTEN, check_formats

    assert ALWAYS_WRITTEN <= set(FigureCanvasBase.get_supported_filetypes())
    assert check_formats(["PNG", ".pdf", "png"]) == ("png", "pdf")
    assert check_formats(["png", "webp"]) == ("png", "webp")  # asks matplotlib
    with pytest.raises(InputError, match="cannot write 'bmpx' figures; use one of .*png"):
        check_formats(["png", "bmpx"])
