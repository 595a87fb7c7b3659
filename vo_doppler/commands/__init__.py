"""One module per ``vo-doppler`` subcommand: each has ``register(subparsers, summary)``.

A subcommand parses its arguments, calls the library and writes outputs; no maths here.
"""
