"""The input gate: user arrays and options checked once, with errors that name the problem."""
