"""Run the grasping-area tool: ``python -m graspexp.area [--option ...] [key=value ...]``."""

import sys

from graspexp.tools.area import main

if __name__ == "__main__":
    sys.exit(main())
