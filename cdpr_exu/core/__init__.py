"""The foundations every layer uses: errors and exit codes, argument checks, geometry, strict output files."""
