"""The application layer: the file pipeline, command line, batch, progress, reports and figures."""
