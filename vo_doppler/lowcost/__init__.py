"""lowcost stage of vo-doppler."""
