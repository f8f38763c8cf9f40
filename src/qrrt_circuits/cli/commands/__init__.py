"""The commands of ``qrrt``, one module each: ``search``, ``plan``, ``reproduce`` (with
``compare-checks``). Each ``cmd_*`` takes the parsed arguments and returns the exit status."""
