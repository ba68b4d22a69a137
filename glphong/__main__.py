"""``python -m glphong``: see `glphong.cli`."""
import sys

from glphong.tools.cli import main

sys.exit(main())
