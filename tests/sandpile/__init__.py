"""tests/sandpile as a package."""
