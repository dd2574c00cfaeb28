"""Crowd annotation: rating tasks out, MTurk results in, aggregation and worker quality."""
