"""``hwpts plant ...``: steady state, sweeps and simulations of the test bed."""


def register(subparsers):
    parser = subparsers.add_parser("plant", help="the simulated HWPTS test bed")
    parser.set_defaults(handler=lambda args: parser.print_help())
