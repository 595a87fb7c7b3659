"""io stage of vo-doppler."""
