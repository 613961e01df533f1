"""``python -m phaseimpact.cli``: the console script ``phaseimpact``."""

if __name__ == "__main__":  # a module scan that imports the package must not run it
    import sys

    from . import main

    sys.exit(main())
