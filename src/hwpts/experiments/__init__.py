"""The paper's experiments on the simulated test bed: sweeps, validation cases, the full pipeline."""
