"""Thin rclpy shells around the core (the only place rclpy is imported)."""
