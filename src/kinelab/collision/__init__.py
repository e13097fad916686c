"""Collisions: the robot's own geometry and the obstacles around it (:mod:`~kinelab.collision.obstacles`),
checked by Pinocchio after a conservative sphere test (:mod:`~kinelab.collision.model`)."""

from kinelab.collision.model import CollisionError, Collisions, Contact, as_collisions, collision_model
from kinelab.collision.obstacles import Environment, Obstacle, ObstacleError

__all__ = ["CollisionError", "Collisions", "Contact", "Environment", "Obstacle", "ObstacleError", "as_collisions",
           "collision_model"]
