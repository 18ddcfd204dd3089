// The run bar's "Params" field: parameters for a run of the page's nodes, one a line, as rosrun
// (`_speed:=0.2`) or a YAML mapping (`speed: 0.2`) writes them. `_name` and `~name` are the
// node's private parameters, `/name` global, `name` in the node's namespace (the root, so
// global too), as <param> in a launch file. Values are typed as rosparam types a command-line
// value: true/false, integers, floats, JSON lists and objects, anything else text.

const LINE = /^([~_/]?[A-Za-z][A-Za-z0-9_/]*)\s*(:=|:)\s*(.*)$/;

/** {params} for the field's text, or {problem} naming the line that cannot be read. */
export function parseParams(text) {
  const params = {};
  const lines = text.split("\n");
  for (let index = 0; index < lines.length; index += 1) {
    const line = lines[index].trim();
    if (line === "" || line.startsWith("#")) continue;
    const match = LINE.exec(line);
    if (!match) return { problem: `params line ${index + 1}: write name:=value or name: value` };
    const [, rawName, , rawValue] = match;
    const name = rawName.startsWith("_") ? `~${rawName.slice(1)}` : rawName;
    if (rawValue === "") return { problem: `params line ${index + 1}: '${rawName}' has no value` };
    const value = typed(rawValue);
    if (value === undefined) return { problem: `params line ${index + 1}: '${rawValue}' is not valid JSON` };
    params[name] = value;
  }
  return { params };
}

function typed(text) {
  if (/^(true|True|TRUE)$/.test(text)) return true;
  if (/^(false|False|FALSE)$/.test(text)) return false;
  if (/^[-+]?\d+$/.test(text)) return Number.parseInt(text, 10);
  if (/^[-+]?(\d+\.\d*|\.\d+|\d+)([eE][-+]?\d+)?$/.test(text)) return Number.parseFloat(text);
  if (/^[[{"]/.test(text)) {
    try {
      return JSON.parse(text);
    } catch {
      return undefined;
    }
  }
  if (/^'.*'$/.test(text)) return text.slice(1, -1);
  return text;
}
