import sys
from pathlib import Path

# the scipy oracle (tests/oracle.py) is imported by tests and benchmarks
sys.path.insert(0, str(Path(__file__).parent))
