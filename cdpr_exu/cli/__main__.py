"""``python -m cdpr_exu.cli``: the ``cdpr`` command."""

import sys

from cdpr_exu.cli.main import main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
