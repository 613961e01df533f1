"""Named impact cases shipped with phaseimpact, one TOML file each (see :mod:`phaseimpact.case`)."""
