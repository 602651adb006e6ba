"""Suite-wide settings.

A cold compiled run normally goes on interpreted while the engine compiles in the background
(`_jit`). Tests that check the compiled engine must run it, so the suite compiles in-process
(`NONSMOOTH_ROD_COMPILE=wait`; a file lock lets one worker compile each part while the other
waits for it); tests/engine/test_compile_policy.py checks the default policy in its own process.
"""
import os

os.environ.setdefault("NONSMOOTH_ROD_COMPILE", "wait")
