"""Progress bars for the long calls (identify, sweep): a tqdm bar where tqdm is
installed and someone watches (a notebook, a terminal), or the caller's function."""

from __future__ import annotations

import sys


def _watched() -> bool:
    """Whether the output is seen as it comes: IPython or Jupyter, or a terminal."""
    ipython = sys.modules.get("IPython")
    if ipython is not None and getattr(ipython, "get_ipython", lambda: None)() is not None:
        return True
    return bool(getattr(sys.stderr, "isatty", lambda: False)())


def _noop() -> None:
    pass


def reporter(progress, what: str, unit: str):
    """``(callback, close)`` for a ``progress`` argument: None (a tqdm bar if tqdm is
    installed and the output watched), True (a tqdm bar, tqdm required), False
    (nothing), or a function called with the counts (then ``close`` does nothing)."""
    if progress is False:
        return None, _noop
    if callable(progress) and progress is not True:
        return progress, _noop
    if progress is not None and progress is not True:
        raise TypeError(f"progress: expected None, True, False or a function, got {type(progress).__name__}")
    try:
        from tqdm.auto import tqdm
    except ImportError:
        if progress is True:
            raise ImportError("progress=True needs tqdm, which is not installed: pip install tqdm") from None
        return None, _noop
    if progress is None and not _watched():
        return None, _noop
    bar = tqdm(desc=what, unit=unit, leave=False)

    def update(done, total, *evaluations):
        if total and bar.total != total:
            bar.total = total
        bar.n = done
        if evaluations:
            bar.set_postfix(evaluations=evaluations[0], refresh=False)
        bar.refresh()

    return update, bar.close
