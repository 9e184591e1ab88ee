"""Neutral scene descriptions shared by kauri and its peers (see bench/peers.py)."""
