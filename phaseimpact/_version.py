"""The package's version, at the bottom of the layers: the engine's cache directory (``_jit``), the
archives and the command line read it without importing the package's face."""

__version__ = "0.2.0"
