"""Heavy modules load only where they are used (issue 13: a warm run under 1 s).

Each check runs in a fresh interpreter and reads ``sys.modules``: what a module
imports is a fact of the code, not a timing, so these tests are exact where a time
limit would be noisy. astropy.coordinates (about 0.3 s) is needed only to read an
angle string, astropy.units/constants (about 0.2 s) only for R_EARTH, GM_EARTH and
G0, scipy.optimize (about 0.4 s) only where a root is found.
"""

import subprocess
import sys

import pytest

SCENE_MODULES = ("dzhanibekov", "foucault", "free_top", "heavy_top", "inertial_oscillation", "projectile",
                 "tower_drop", "turntable")
HEAVY = ("astropy", "astropy.units", "astropy.constants", "astropy.coordinates", "scipy", "scipy.optimize",
         "scipy.linalg", "scipy.special")


def loaded_after(code: str) -> set:
    """The HEAVY modules in ``sys.modules`` after running ``code`` in a fresh process."""
    probe = f"{code}\nimport sys; print('LOADED', ','.join(m for m in {HEAVY!r} if m in sys.modules))"
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    line = [ln for ln in res.stdout.splitlines() if ln.startswith("LOADED")][-1]
    return set(filter(None, line[len("LOADED "):].split(",")))


def test_importing_the_foucault_scene_imports_neither_astropy_nor_scipy():
    loaded = loaded_after("import rotframe.scenes.foucault")
    assert "astropy.coordinates" not in loaded and "scipy.optimize" not in loaded
    # stronger: the scene's import needs neither package at all (numpy, then numba when it runs)
    assert loaded == set()


@pytest.mark.parametrize("scene", SCENE_MODULES)
def test_no_scene_module_imports_astropy_coordinates_or_scipy_optimize(scene):
    loaded = loaded_after(f"import rotframe.scenes.{scene}")
    assert not loaded & {"astropy.coordinates", "scipy.optimize"}, loaded


@pytest.mark.parametrize("scene", SCENE_MODULES)
def test_no_scene_module_imports_numba(scene):
    # numba (about 0.3 s) is imported by the runs that compile, not by listing or describing a scene
    probe = f"import sys, rotframe.scenes.{scene}\nprint('numba' in sys.modules)"
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["False"]


def test_earth_rotation_and_normal_gravity_need_no_astropy():
    loaded = loaded_after("from rotframe.earth import OMEGA_EARTH, omega_enu, normal_gravity, geocentric_latitude, "
                          "ecef_to_enu_matrix, SITES, Site\n"
                          "omega_enu(0.8); normal_gravity(0.8); Site.from_any('pantheon-paris')\n"
                          "import rotframe.analytic")
    assert loaded == set()


def test_astropy_constants_are_read_on_first_use_without_astropy_coordinates():
    code = ("import rotframe.earth.constants as c, sys\n"
            "assert 'astropy' not in sys.modules\n"
            "r = c.R_EARTH\n"
            "import astropy.constants as k, astropy.units as u\n"
            "assert r == float(k.R_earth.to_value(u.m)) and c.GM_EARTH == float(k.GM_earth.to_value(u.m**3 / u.s**2))\n"
            "assert c.G0 == float(k.g0.to_value(u.m / u.s**2)) and 'R_EARTH' in vars(c)  # read once, then kept")
    loaded = loaded_after(code)
    assert {"astropy.units", "astropy.constants"} <= loaded and "astropy.coordinates" not in loaded


def test_a_parser_imports_astropy_when_it_reads_a_string():
    loaded = loaded_after("import math\nfrom rotframe.earth import parse_latitude\n"
                          "assert abs(parse_latitude('50d30m') - math.radians(50.5)) < 1e-15")
    assert "astropy.coordinates" in loaded


def test_earth_names_all_resolve_lazily():
    code = ("import rotframe.earth as e\nfrom rotframe.earth import *  # noqa: F403\n"
            "missing = [n for n in e.__all__ if n not in dir(e) or getattr(e, n) is None]\n"
            "assert not missing, missing\n"
            "assert e.gravity.__name__ == 'rotframe.earth.gravity' and e.local_frame.omega_enu is e.omega_enu\n"
            "try:\n    e.no_such_name\nexcept AttributeError:\n    pass\nelse:\n    raise SystemExit(1)")
    loaded_after(code)


def test_a_warm_foucault_run_imports_no_astropy():
    loaded = loaded_after("import io, contextlib\nfrom rotframe.app.cli import main\n"
                          "with contextlib.redirect_stdout(io.StringIO()):\n"
                          "    assert main(['run', 'foucault', '--set', 'duration=40', '--no-record', '--json']) == 0")
    assert not {m for m in loaded if m.startswith("astropy")}, loaded
    assert "scipy.optimize" not in loaded
    assert "scipy.special" not in loaded  # the theory's K(m) is an arithmetic-geometric mean (0.08 s less)


def test_names_moved_out_of_local_frame_still_import_from_it():
    # effective_gravity_enu and plumb_tilt moved to earth.gravity, enu_to_ecef and ecef_to_enu to
    # earth.ecef (so that local_frame needs no astropy); the old imports give the same functions
    from rotframe.earth import ecef, gravity
    from rotframe.earth.local_frame import ecef_to_enu, effective_gravity_enu, enu_to_ecef, plumb_tilt

    assert effective_gravity_enu is gravity.effective_gravity_enu and plumb_tilt is gravity.plumb_tilt
    assert enu_to_ecef is ecef.enu_to_ecef and ecef_to_enu is ecef.ecef_to_enu
