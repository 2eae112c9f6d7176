"""cdpr-exu: cable-driven parallel robots with lumped-mass cables, simulated with Exudyn."""
__version__ = "0.1.0"
