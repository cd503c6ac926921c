import sys

from warpcaustics.cli import main

sys.exit(main())
