"""Simulation stage: the compiled kernel, its random streams and the plain-Python reference."""
