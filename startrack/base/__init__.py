"""What every layer stands on: the errors and exit codes, units, the user cache directory, lazy exports, output paths checked before work, the allocator of a long-lived solver."""
