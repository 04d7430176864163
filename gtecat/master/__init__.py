"""The bus master: process image, backends, clocks, master log, slave factory.

Knows nothing of the controller above it (axes, motion, GT layer).
"""
