"""Vendor three.js into ``stylemotion/viewer/vendor/`` at a pinned version, with its licence.

    python scripts/vendor_three.py            # needs node/npm and the npm registry, once, by a maintainer

The viewer page must open from disk (``file://``), where browsers refuse ES-module imports between
files. So the npm package ``three`` (core, ``OrbitControls``, ``BVHLoader``) is bundled by esbuild
(also pinned) into one classic script that defines the global ``THREE``:
``vendor/three.bundle.min.js``; three's ``LICENSE`` is copied beside it and ``vendor/VERSION.json``
records the versions and the SHA-256 of the bundle. The vendored files are committed, so a
``pip install`` of stylemotion ships them and nothing is fetched at run time.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

THREE_VERSION = "0.187.0"
ESBUILD_VERSION = "0.28.2"
VENDOR = Path(__file__).resolve().parent.parent / "stylemotion" / "viewer" / "vendor"

ENTRY = """\
export * from "three";
export { OrbitControls } from "three/addons/controls/OrbitControls.js";
export { BVHLoader } from "three/addons/loaders/BVHLoader.js";
"""


def run(cmd: list[str], cwd: Path) -> None:
    print("+", " ".join(cmd), flush=True)
    subprocess.run(cmd, cwd=cwd, check=True)


def main() -> int:
    if shutil.which("npm") is None:
        print("vendor_three: error: npm is not on PATH", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory(prefix="vendor_three.") as tmp_name:
        tmp = Path(tmp_name)
        (tmp / "package.json").write_text(json.dumps({"name": "vendor-three", "private": True}))
        run(["npm", "install", "--no-audit", "--no-fund", "--save-exact",
             f"three@{THREE_VERSION}", f"esbuild@{ESBUILD_VERSION}"], tmp)
        installed = json.loads((tmp / "node_modules" / "three" / "package.json").read_text())["version"]
        if installed != THREE_VERSION:
            print(f"vendor_three: error: npm installed three {installed}, expected {THREE_VERSION}", file=sys.stderr)
            return 1
        (tmp / "entry.js").write_text(ENTRY)
        bundle = tmp / "three.bundle.min.js"
        run([str(tmp / "node_modules" / ".bin" / "esbuild"), "entry.js", "--bundle", "--format=iife",
             "--global-name=THREE", "--minify", "--legal-comments=inline", f"--outfile={bundle.name}"], tmp)
        staging = Path(tempfile.mkdtemp(prefix=".vendor.", dir=VENDOR.parent))
        staging.chmod(0o755)  # mkdtemp makes it private; the package folder is not
        shutil.copy2(bundle, staging / bundle.name)
        shutil.copy2(tmp / "node_modules" / "three" / "LICENSE", staging / "LICENSE")
        digest = hashlib.sha256(bundle.read_bytes()).hexdigest()
        (staging / "VERSION.json").write_text(json.dumps({
            "three": THREE_VERSION, "esbuild": ESBUILD_VERSION, "bundle": bundle.name, "sha256": digest,
            "exports": "three core + OrbitControls + BVHLoader as the global THREE (IIFE)",
            "made_by": "scripts/vendor_three.py"}, indent=1) + "\n")
        if VENDOR.exists():
            shutil.rmtree(VENDOR)
        staging.replace(VENDOR)
    print(f"vendored three {THREE_VERSION} into {VENDOR} ({(VENDOR / bundle.name).stat().st_size / 1e6:.2f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
