"""``python -m feederkit``: the ``feederkit`` command, through the console script's entry."""

from feederkit.cli.app import run

if __name__ == "__main__":
    run()
