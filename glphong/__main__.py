"""``python -m glphong``: see `glphong.tools.cli`."""
import sys

from glphong.tools.cli import main

sys.exit(main())
