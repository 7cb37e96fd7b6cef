"""Readers and writers: the only place where datasheet units meet the SI interior."""
