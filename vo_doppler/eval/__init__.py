"""eval stage of vo-doppler."""
