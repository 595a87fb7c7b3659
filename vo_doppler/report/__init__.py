"""Figures and HTML reports (matplotlib; the only package that draws)."""
