"""The command line (`cli`, `expressions`): glphong's users, not its core.  What ``glphong bench`` runs is
`glphong.bench`.
"""
