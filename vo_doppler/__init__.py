"""vo-doppler: monocular visual odometry with heading corrected by GNSS Doppler."""

__version__ = "0.1.0"
