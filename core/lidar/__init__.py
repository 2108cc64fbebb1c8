"""LiDAR science: ground filter, DSM, roof planes, LiDAR control points and lines."""
