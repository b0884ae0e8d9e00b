"""Closed-form reference solutions for tests and benchmarks (see ``closed_form``)."""
