"""Chung & Ooi (2011) benchmark: runs, analysis, figures and report (CLI: scripts/chung_ooi.py)."""
