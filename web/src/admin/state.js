// What several panels share: who is logged in, the users, exercises and courses. Each list is
// loaded on demand and refreshed after a change; panels subscribe to redraw their pickers.

import { api } from "../common/api.js";

export const state = {
  me: null,
  users: [],
  exercises: [],
  genericChecks: [],
  courses: [],
  robots: [],
  worlds: [],
};

const listeners = { users: new Set(), exercises: new Set(), courses: new Set() };

export function subscribe(kind, listener) {
  listeners[kind].add(listener);
}

function emit(kind) {
  for (const listener of listeners[kind]) {
    try {
      listener(state[kind]);
    } catch (error) {
      console.error(error); // eslint-disable-line no-console
    }
  }
}

export async function loadUsers() {
  state.users = (await api("/api/admin/users")).users;
  emit("users");
  return state.users;
}

export async function loadExercises() {
  const answer = await api("/api/admin/exercises");
  state.exercises = answer.exercises;
  state.genericChecks = answer.generic_checks || [];
  emit("exercises");
  return state.exercises;
}

export async function loadCourses() {
  state.courses = (await api("/api/admin/courses")).courses;
  emit("courses");
  return state.courses;
}

export async function loadCatalog() {
  const [robots, worlds] = await Promise.all([api("/api/robots"), api("/api/worlds")]);
  state.robots = robots;
  state.worlds = worlds;
}

export function userName(id) {
  const user = state.users.find((u) => u.id === id);
  return user ? user.name : null;
}

export function exerciseTitle(id) {
  const exercise = state.exercises.find((e) => e.id === id);
  return exercise ? exercise.title || id : null;
}
