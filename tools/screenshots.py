"""The first frame of every scene's recording, as rerun's own viewer opens it (docs/recordings/*.png).

Each scene runs with its defaults and writes its recording; rerun's viewer then opens it headless
and takes a screenshot at start-up (``rerun FILE --headless --renderer vulkan --screenshot-to``)
with mesa's software Vulkan driver (Debian: ``apt-get install mesa-vulkan-drivers``). The
pictures are scaled to 1280 pixels wide and kept in docs/recordings, shown by
docs/guide/recordings.md. Run it again after changing what a scene records::

    python tools/screenshots.py                 # every scene
    python tools/screenshots.py turntable cr3bp # some

The viewer's own notices (the software renderer, the backend) sit at the top right of each
picture: rerun shows them at start-up and the screenshot is taken then.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "recordings"
WIDTH = 1280


def shoot(scene: str, folder: Path) -> Path:
    """Record ``scene`` with its defaults in ``folder`` and screenshot its first frame into docs/recordings."""
    rrd = folder / f"{scene}.rrd"
    subprocess.run([sys.executable, "-m", "rotframe", "run", scene, "--out", str(rrd)], check=True, cwd=folder,
                   stdout=subprocess.DEVNULL)
    raw = folder / f"{scene}.png"
    env = dict(os.environ, XDG_RUNTIME_DIR=os.environ.get("XDG_RUNTIME_DIR", str(folder)))
    subprocess.run([shutil.which("rerun") or "rerun", str(rrd), "--headless", "--renderer", "vulkan",
                    "--window-size", "1600x900", "--screenshot-to", str(raw)], check=True, env=env, timeout=300,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    from PIL import Image

    image = Image.open(raw)
    image = image.resize((WIDTH, round(image.height * WIDTH / image.width)), Image.LANCZOS)
    target = OUT / f"{scene}.png"
    image.convert("RGB").quantize(colors=256).save(target, optimize=True)
    return target


def main(argv=None) -> int:
    import rotframe

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", help="scene names (default: every built-in scene)")
    args = parser.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rotframe-shots-") as tmp:
        for scene in args.scenes or rotframe.scenarios():
            print(shoot(scene, Path(tmp)).relative_to(ROOT))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
