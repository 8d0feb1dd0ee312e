# SPDX-License-Identifier: MIT
# The shim's own tests: its PlantGL geometry imported as plain Python (the package lpyshim beside
# this folder), without the engine. Run: python3 -m pytest src/lsys/py/tests
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
