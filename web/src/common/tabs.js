// Accessible tabs (WAI-ARIA tabs pattern): role=tablist with role=tab buttons that control
// role=tabpanel elements; arrow keys, Home and End move between tabs; one tab is in the Tab order.

/**
 * Wire an existing tablist: its buttons carry aria-controls naming their panels.
 * Returns {select(id), current()}; `onChange(panelId)` is called after every change.
 */
export function tabs(tablist, onChange = () => {}) {
  const buttons = () => [...tablist.querySelectorAll('[role="tab"]')];
  let current = null;

  function select(panelId, { focus = false } = {}) {
    for (const button of buttons()) {
      const selected = button.getAttribute("aria-controls") === panelId;
      button.setAttribute("aria-selected", String(selected));
      button.tabIndex = selected ? 0 : -1;
      const panel = document.getElementById(button.getAttribute("aria-controls"));
      if (panel) panel.hidden = !selected;
      if (selected && focus) button.focus();
    }
    if (current !== panelId) {
      current = panelId;
      onChange(panelId);
    }
  }

  tablist.addEventListener("click", (event) => {
    const button = event.target.closest('[role="tab"]');
    if (button && tablist.contains(button)) select(button.getAttribute("aria-controls"));
  });
  tablist.addEventListener("keydown", (event) => {
    const all = buttons();
    const index = all.indexOf(document.activeElement);
    if (index < 0) return;
    const next = {
      ArrowRight: (index + 1) % all.length,
      ArrowLeft: (index - 1 + all.length) % all.length,
      Home: 0,
      End: all.length - 1,
    }[event.key];
    if (next === undefined) return;
    event.preventDefault();
    select(all[next].getAttribute("aria-controls"), { focus: true });
  });

  const initial = buttons().find((b) => b.getAttribute("aria-selected") === "true") || buttons()[0];
  if (initial) select(initial.getAttribute("aria-controls"));
  return { select, current: () => current };
}
