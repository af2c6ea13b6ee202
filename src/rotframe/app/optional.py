"""Optional packages: imported where a feature needs them, refused in one line when missing or broken.

Each optional package belongs to an extra of ``pyproject.toml``. `need` imports it for a feature
and turns any failure (not installed, or installed but broken: a wheel built for another numpy,
a missing shared library) into a `rotframe.errors.MissingExtraError` naming the package, what needed
it, why, and the extra that installs it, so that the command exits with code 2 and one line
instead of an internal error. `missing_package` lets the command line's last resort say the same
for an import that failed where no `need` guarded it.
"""

from __future__ import annotations

import importlib

from rotframe.errors import MissingExtraError

__all__ = ["EXTRAS", "need", "missing_package"]

#: top-level package -> the extra of pyproject.toml that installs it
EXTRAS = {"pyarrow": "sweep", "pandas": "sweep", "matplotlib": "plot", "distributed": "sweep", "dask": "sweep",
          "threadpoolctl": "sweep", "tqdm": "notebook", "ipykernel": "notebook", "jax": "bench",
          "diffrax": "bench", "cupy": "bench", "mpmath": "test"}


def need(module: str, what: str, extra: str | None = None):
    """Import ``module`` (``"pyarrow.parquet"``) for ``what`` (``"rotframe sweep"``); a one-line error if it fails.

    ``extra``: the extra to name when not the package's own in `EXTRAS`.
    """
    try:
        return importlib.import_module(module)
    except Exception as exc:  # ImportError, or whatever a broken package raises while importing
        raise MissingExtraError(_message(module, what, exc, extra)) from None


def _culprit(exc: BaseException) -> str | None:
    """The optional package whose own import-time code raised ``exc`` (the deepest such frame), else None."""
    found = None
    tb = exc.__traceback__
    while tb is not None:
        code = tb.tb_frame.f_code
        if code.co_name == "<module>":
            parts = code.co_filename.replace("\\", "/").split("/")
            for top in EXTRAS:
                if top in parts[:-1]:
                    found = top
        tb = tb.tb_next
    name = (getattr(exc, "name", None) or "").split(".")[0]
    if isinstance(exc, ImportError) and name in EXTRAS:
        found = name
    return found


def _message(module: str, what: str, exc: BaseException, extra: str | None = None) -> str:
    top = _culprit(exc) or module.split(".")[0]
    extra = extra or EXTRAS.get(top)
    install = f"pip install 'rotframe[{extra}]'" if extra else f"pip install {top}"
    if isinstance(exc, ModuleNotFoundError) and (exc.name or "").split(".")[0] == top:
        why = "is not installed"
    else:
        why = f"cannot be imported ({type(exc).__name__}: {' '.join(str(exc).split())[:120]})"
    return f"{what} needs the optional package {top!r}, which {why}; {install}"


def missing_package(exc: BaseException) -> str | None:
    """The one-line message for an exception raised while importing an optional package, else None."""
    top = _culprit(exc)
    return None if top is None else _message(top, "this command", exc)
