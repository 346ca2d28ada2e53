"""ctest entry of the Python tests: runs pytest on this folder with the module built in
BUILD_PYTHON_DIR; exits 77 (ctest: skipped) when numpy or pytest is not installed.
    run.py BUILD_PYTHON_DIR POMAR_TOOL SAMPLES_DIR"""
import os
import subprocess
import sys

build, tool, samples = sys.argv[1:4]
for module in ("numpy", "pytest"):
    try:
        __import__(module)
    except ImportError:
        print(f"python_module: skipped: {module} is not installed (python3-{module})")
        sys.exit(77)
env = dict(os.environ, PYTHONPATH=build + os.pathsep + os.environ.get("PYTHONPATH", ""),
           POMAR_TOOL=tool, POMAR_SAMPLES=samples)
here = os.path.dirname(os.path.abspath(__file__))
sys.exit(subprocess.call([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", here],
                         env=env))
