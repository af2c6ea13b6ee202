"""astropy offline: a context in which astropy may not reach the network or download IERS tables.

Nothing in [`rotframe.earth`][rotframe.earth] calls what needs the network or the IERS tables (no
``EarthLocation.of_site``, ``Time.ut1``, GCRS); the parsers run inside
[`astropy_offline`][rotframe.earth.astropy_offline] all the same, so that a future astropy default cannot make
them reach out.
"""

from __future__ import annotations

import contextlib
import threading

__all__ = ["astropy_offline"]

_OFFLINE_LOCK = threading.RLock()


@contextlib.contextmanager
def astropy_offline():
    """Run a block with astropy forbidden to reach the network or download IERS tables.

    Sets ``astropy.utils.data.conf.allow_internet`` and
    ``astropy.utils.iers.conf.auto_download`` to False with ``set_temp``, restoring the
    previous values on exit; a re-entrant lock keeps concurrent threads from restoring
    each other's values, so the user's configuration is never changed.
    """
    from astropy.utils import data as _data
    from astropy.utils import iers as _iers

    with _OFFLINE_LOCK:
        with _data.conf.set_temp("allow_internet", False), _iers.conf.set_temp(
            "auto_download", False
        ):
            yield
