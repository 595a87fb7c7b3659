"""sim stage of vo-doppler."""
