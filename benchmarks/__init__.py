"""Speed and accuracy benchmarks: ``python -m benchmarks [NAME ...]`` (or ``make bench``)."""
