"""gnss stage of vo-doppler."""
