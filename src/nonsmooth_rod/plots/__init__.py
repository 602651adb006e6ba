"""Figures and animations of any scene's run (the rod's own figures live in rod/plotting.py)."""
