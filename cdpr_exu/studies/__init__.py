"""Studies over many runs: parameter sweeps, accuracy, robustness, learning and the controller comparison."""
