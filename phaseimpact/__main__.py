"""``python -m phaseimpact``: the command line."""

if __name__ == "__main__":  # a module scan that imports the package must not run it
    import sys

    from ._entry import main

    sys.exit(main())
