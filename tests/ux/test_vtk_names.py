#!/usr/bin/env python3
"""test_vtk_names.py FLEXMBD SCENE OUTDIR — the animation of a scene whose file name holds XML's
special characters (& < > " '): the collection file must still be XML whose DataSets name the
frames written (engine/vtk.c escapes the names; they went in raw and broke the .pvd). The scene is
copied under such a name and checked by test_vtk.py in full."""
import os
import shutil
import subprocess
import sys

flexmbd, scene, out = sys.argv[1:4]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
odd = os.path.join(out, "blade & hub <\"v2\">'s.yaml")
shutil.copy(scene, odd)
here = os.path.dirname(os.path.abspath(__file__))
r = subprocess.run([sys.executable, os.path.join(here, "test_vtk.py"), flexmbd, odd, os.path.join(out, "check")])
sys.exit(r.returncode)
