"""Experiment protocols: each cell's search poses and the papers' start poses."""
