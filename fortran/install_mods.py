#!/usr/bin/env python3
"""Install libfrirom's Fortran .mod files: install_mods.py BUILD_PRIVATE_DIR REL_MODDIR.

meson writes module files into the target's private directory and does not install them;
legacy codes need them for `use frirom_aft`.
"""
import os
import shutil
import sys
from pathlib import Path

src, moddir = Path(sys.argv[1]), Path(sys.argv[2])
dest = Path(os.environ["MESON_INSTALL_DESTDIR_PREFIX"]) / moddir
dest.mkdir(parents=True, exist_ok=True)
mods = sorted(src.glob("*.mod"))
if not mods:
    sys.exit(f"install_mods.py: no .mod files in {src}")
for mod in mods:
    shutil.copy2(mod, dest / mod.name)
    print(f"Installing {mod.name} to {dest}")
