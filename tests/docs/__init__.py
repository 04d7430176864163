"""Tests of the documentation (tutorial pages run)."""
