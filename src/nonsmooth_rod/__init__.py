"""nonsmooth-rod: nonsmooth contact dynamics with two-coefficient Coulomb friction."""
__version__ = "0.1.0"
