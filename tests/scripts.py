"""Standalone scripts (benchmarks/*.py, examples/*.py: not a package) imported as modules, for
the tests that run their quick modes or call their functions."""
import importlib.util
from pathlib import Path


def load_script(path) -> object:
    """The script at `path` imported as a module named after its file."""
    path = Path(path)
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
