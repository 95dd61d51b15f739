"""Del Cid's (2015) MEPA sandpiles (her Table 4.3): the campaign's plan, the discharge scene, the
angle of repose and the report (docs/sandpile.md)."""
