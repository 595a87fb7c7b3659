"""heading stage of vo-doppler."""
