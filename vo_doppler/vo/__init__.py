"""vo stage of vo-doppler."""
