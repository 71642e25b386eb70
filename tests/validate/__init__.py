"""Tests of jointcal.validate, one file per module (a package, so that their names may repeat other folders')."""
