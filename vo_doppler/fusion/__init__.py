"""fusion stage of vo-doppler."""
