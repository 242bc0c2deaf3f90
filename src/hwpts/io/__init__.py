"""Files: datasets (CSV, Parquet, MATLAB .mat) and model files (JSON). The only layer that touches files."""
